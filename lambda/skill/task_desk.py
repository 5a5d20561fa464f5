"""The skill's port to the fleet dispatcher, `TaskDesk`, and its two adapters.

The dispatcher (docs/dispatch.md) gives tasks without a robot's name to the best free robot
or queues them, and keeps the zones closed at run time. The skill only submits an order,
reads the tasks, cancels one, and reads, closes and opens zones:

- `HttpTaskDesk`: the local stack's data plane, `POST|GET {data_endpoint}/vahr/tasks`,
  `DELETE {data_endpoint}/vahr/tasks/{id}`, `GET {data_endpoint}/vahr/zones` and `POST
  {data_endpoint}/vahr/zones/{zone}` (urllib; `vahr up`);
- `LambdaTaskDesk`: the dispatcher function on AWS, invoked synchronously with
  `{"operation": "submit"|"tasks"|"cancel"|"zones"|"zone"|"service"|"set_service"|"charge",
  ...}` and answering `{"status",
  "body"}`, the same status and body as the local routes (lambda/dispatcher/requests.py).

`task_desk(config)` picks one: the function when `VAHR_DISPATCHER_FUNCTION` is set (the CDK
stack sets it), else the data endpoint when it is a local `http://` one, else None (no
dispatcher: the handlers say so). A refused request (a bad order, an unknown task) is
`TaskRefused` with the dispatcher's one line; a dispatcher that cannot be reached is a
`GatewayError`, which the catch-all handler speaks.
"""

from __future__ import annotations

import json
import urllib.error
import urllib.request
from typing import TYPE_CHECKING, Any, Protocol
from urllib.parse import quote

import msgspec

from skill.errors import GatewayError, SkillError
from vahr.dispatch import DispatchErrorCode, Order, ServiceChange, Submission, Task, ZoneChange
from vahr.protocol.audit import RECORDED_BY_HEADER

if TYPE_CHECKING:
    from skill.config import SkillConfig

# The skill answers within Alexa's 8 s; a dispatcher slower than this is unreachable.
DESK_TIMEOUT_S = 4.0
TASKS_PATH = "/vahr/tasks"
ZONES_PATH = "/vahr/zones"
SERVICE_PATH = "/vahr/service"
CHARGE_PATH = "/vahr/charge"


class TaskRefused(SkillError):
    """The dispatcher refused the request; `str(error)` is its one-line reason and `error`
    the `DispatchError.code` of an order it refused (None for other refusals)."""

    def __init__(self, status: int, message: str, error: DispatchErrorCode | None = None) -> None:
        super().__init__(message)
        self.status = status
        self.error = error


class TaskDesk(Protocol):
    """Where the skill hands tasks to the fleet dispatcher."""

    def submit(self, order: Order) -> Submission:
        """Give the order's tasks to robots now or queue them; TaskRefused when it cannot."""
        ...

    def tasks(self) -> list[Task]:
        """The tasks robots hold, then the queue, next first."""
        ...

    def cancel(self, task_id: str) -> Task | None:
        """Cancel an open task (its robot, if any, is stopped); None when it is not open."""
        ...

    def closed_zones(self) -> list[str]:
        """The zones closed now."""
        ...

    def set_zone(self, zone: str, *, closed: bool) -> ZoneChange:
        """Close or open a zone; TaskRefused for a zone the fleet does not have."""
        ...

    def out_of_service(self) -> list[str]:
        """The robots taken out of service now."""
        ...

    def set_service(self, thing: str, *, in_service: bool) -> ServiceChange:
        """Take a robot out of service or put it back; TaskRefused for an unknown robot."""
        ...

    def charge(self, thing: str) -> Task:
        """Send a robot to the nearest free charger now; TaskRefused (`no_charger`,
        `out_of_service`, ...) when it cannot go."""
        ...


class _TaskList(msgspec.Struct):
    tasks: list[Task]


class _Closed(msgspec.Struct):
    closed: list[str]


class _Cancelled(msgspec.Struct):
    task: Task


class _OutOfService(msgspec.Struct):
    out_of_service: list[str]


class _Refusal(msgspec.Struct):
    message: str = "the dispatcher refused the request"
    error: DispatchErrorCode | None = None


def _read(status: int, body: bytes | Any, kind: type[Any]) -> Any:
    """The answer's body as `kind`, or TaskRefused for a 4xx answer."""
    decode = msgspec.json.decode if isinstance(body, bytes) else msgspec.convert
    if status >= 400:
        try:
            refusal = decode(body, type=_Refusal)
        except (msgspec.ValidationError, msgspec.DecodeError):
            refusal = _Refusal()
        raise TaskRefused(status, refusal.message, refusal.error)
    try:
        return decode(body, type=kind)
    except (msgspec.ValidationError, msgspec.DecodeError) as err:
        raise GatewayError(f"the dispatcher's answer is not readable: {err}") from err


class HttpTaskDesk:
    """The local data plane's `/vahr/tasks` routes."""

    def __init__(self, endpoint: str, *, timeout_s: float = DESK_TIMEOUT_S) -> None:
        self.url = endpoint.rstrip("/") + TASKS_PATH
        self.zones_url = endpoint.rstrip("/") + ZONES_PATH
        self.service_url = endpoint.rstrip("/") + SERVICE_PATH
        self.charge_url = endpoint.rstrip("/") + CHARGE_PATH
        self.timeout_s = timeout_s

    def _call(self, method: str, url: str, body: bytes | None = None) -> tuple[int, bytes]:
        request = urllib.request.Request(url, data=body, method=method)  # noqa: S310 - http(s) only
        request.add_header("Content-Type", "application/json")
        # The skill records its own requests in the trail, with who asked.
        request.add_header(RECORDED_BY_HEADER, "skill")
        try:
            with urllib.request.urlopen(request, timeout=self.timeout_s) as response:  # noqa: S310
                return response.status, response.read()
        except urllib.error.HTTPError as err:
            if err.code >= 500:
                raise GatewayError(f"the dispatcher failed: HTTP {err.code}") from err
            return err.code, err.read()
        except (urllib.error.URLError, OSError) as err:
            raise GatewayError(f"the dispatcher is unreachable: {err}") from err

    def submit(self, order: Order) -> Submission:
        status, body = self._call("POST", self.url, msgspec.json.encode(order))
        return _read(status, body, Submission)  # type: ignore[no-any-return]

    def tasks(self) -> list[Task]:
        status, body = self._call("GET", self.url)
        return _read(status, body, _TaskList).tasks  # type: ignore[no-any-return]

    def cancel(self, task_id: str) -> Task | None:
        status, body = self._call("DELETE", f"{self.url}/{quote(task_id, safe='')}")
        if status == 404:
            return None
        return _read(status, body, _Cancelled).task  # type: ignore[no-any-return]

    def closed_zones(self) -> list[str]:
        status, body = self._call("GET", self.zones_url)
        return _read(status, body, _Closed).closed  # type: ignore[no-any-return]

    def set_zone(self, zone: str, *, closed: bool) -> ZoneChange:
        url = f"{self.zones_url}/{quote(zone, safe='')}"
        status, body = self._call("POST", url, msgspec.json.encode({"closed": closed}))
        return _read(status, body, ZoneChange)  # type: ignore[no-any-return]

    def out_of_service(self) -> list[str]:
        status, body = self._call("GET", self.service_url)
        return _read(status, body, _OutOfService).out_of_service  # type: ignore[no-any-return]

    def set_service(self, thing: str, *, in_service: bool) -> ServiceChange:
        url = f"{self.service_url}/{quote(thing, safe='')}"
        status, body = self._call("POST", url, msgspec.json.encode({"in_service": in_service}))
        return _read(status, body, ServiceChange)  # type: ignore[no-any-return]

    def charge(self, thing: str) -> Task:
        status, body = self._call("POST", f"{self.charge_url}/{quote(thing, safe='')}", b"{}")
        return _read(status, body, _Cancelled).task  # type: ignore[no-any-return]


class LambdaTaskDesk:
    """The dispatcher function, invoked synchronously (boto3's lambda client)."""

    def __init__(self, function_name: str, client: Any = None) -> None:
        if client is None:
            import boto3  # only this adapter needs the lambda client
            from botocore.config import Config

            client = boto3.client(
                "lambda",
                config=Config(
                    connect_timeout=2, read_timeout=DESK_TIMEOUT_S, retries={"max_attempts": 1}
                ),
            )
        self.function_name = function_name
        self.client = client

    def _invoke(self, request: dict[str, Any]) -> tuple[int, Any]:
        from botocore.exceptions import BotoCoreError, ClientError

        try:
            response = self.client.invoke(
                FunctionName=self.function_name,
                InvocationType="RequestResponse",
                Payload=json.dumps(request).encode(),
            )
            payload = json.loads(response["Payload"].read() or b"{}")
        except (BotoCoreError, ClientError, ValueError) as err:
            raise GatewayError(f"the dispatcher function could not be invoked: {err}") from err
        if response.get("FunctionError") or not isinstance(payload, dict):
            raise GatewayError(f"the dispatcher function failed: {str(payload)[:200]}")
        status = payload.get("status")
        if not isinstance(status, int):
            raise GatewayError("the dispatcher function's answer has no status")
        return status, payload.get("body")

    def submit(self, order: Order) -> Submission:
        status, body = self._invoke({"operation": "submit", "order": msgspec.to_builtins(order)})
        return _read(status, body, Submission)  # type: ignore[no-any-return]

    def tasks(self) -> list[Task]:
        status, body = self._invoke({"operation": "tasks"})
        return _read(status, body, _TaskList).tasks  # type: ignore[no-any-return]

    def cancel(self, task_id: str) -> Task | None:
        status, body = self._invoke({"operation": "cancel", "task_id": task_id})
        if status == 404:
            return None
        return _read(status, body, _Cancelled).task  # type: ignore[no-any-return]

    def closed_zones(self) -> list[str]:
        status, body = self._invoke({"operation": "zones"})
        return _read(status, body, _Closed).closed  # type: ignore[no-any-return]

    def set_zone(self, zone: str, *, closed: bool) -> ZoneChange:
        status, body = self._invoke({"operation": "zone", "zone": zone, "closed": closed})
        return _read(status, body, ZoneChange)  # type: ignore[no-any-return]

    def out_of_service(self) -> list[str]:
        status, body = self._invoke({"operation": "service"})
        return _read(status, body, _OutOfService).out_of_service  # type: ignore[no-any-return]

    def set_service(self, thing: str, *, in_service: bool) -> ServiceChange:
        request = {"operation": "set_service", "thing": thing, "in_service": in_service}
        status, body = self._invoke(request)
        return _read(status, body, ServiceChange)  # type: ignore[no-any-return]

    def charge(self, thing: str) -> Task:
        status, body = self._invoke({"operation": "charge", "thing": thing})
        return _read(status, body, _Cancelled).task  # type: ignore[no-any-return]


def task_desk(config: SkillConfig) -> TaskDesk | None:
    """The dispatcher this configuration reaches, if any (see the module's docstring)."""
    if config.dispatcher_function:
        return LambdaTaskDesk(config.dispatcher_function)
    endpoint = config.data_endpoint
    if endpoint is not None and endpoint.startswith("http://"):
        return HttpTaskDesk(endpoint)
    return None
