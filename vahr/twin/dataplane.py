"""The local AWS IoT data plane: the HTTP API boto3's `iot-data` client talks to unchanged.

Point boto3 at it with `AWS_ENDPOINT_URL_IOT_DATA_PLANE=http://127.0.0.1:PORT`. It serves
Publish (to the local broker, QoS and retain honoured), Get/Update/DeleteThingShadow
(classic and named) and ListNamedShadowsForThing with AWS's status codes, error shapes and
`x-amzn-ErrorType` names (so boto3 raises `ResourceNotFoundException`, `ConflictException`,
...). It listens on 127.0.0.1 only and checks no signature, so what a web page could make
the operator's browser send is refused before anything runs (`vahr.twin.browser_guard`):
a foreign `Host` (DNS rebinding), a foreign `Origin` or `Sec-Fetch-Site`, and a write that
is neither JSON nor signed with SigV4 (boto3 and the AWS CLI sign every request).

It also answers the IoT control plane's fleet-indexing calls under `/indices`
(`vahr.twin.fleet_index_api`), so boto3's `iot` client pointed here can search the fleet.

Paths under `/vahr/` are the local stack's own (the Alexa simulator's `say`, health and
the billing meter; `/vahr/dashboard` redirects to the operator station); AWS uses none of
them.
"""

from __future__ import annotations

import json
import logging
from collections.abc import Callable, Mapping
from typing import TYPE_CHECKING, Any
from urllib.parse import parse_qs, unquote, urlsplit

from vahr.errors import VahrError
from vahr.plumbing.http_server import QuietHandler, QuietServer, ServerThread
from vahr.plumbing.ports import LOOPBACK, ensure_free
from vahr.protocol import topics
from vahr.twin.browser_guard import BrowserGuard
from vahr.twin.fleet_index_api import FleetIndexApi
from vahr.twin.shadow_store import MAX_REQUEST_BYTES, ShadowError

if TYPE_CHECKING:
    from vahr.twin.meter import Meter
    from vahr.twin.shadow_service import ShadowService

log = logging.getLogger(__name__)

# botocore reads the error code from this header; the names are the iot-data model's.
ERROR_TYPES = {
    400: "InvalidRequestException",
    401: "UnauthorizedException",
    404: "ResourceNotFoundException",
    405: "MethodNotAllowedException",
    409: "ConflictException",
    413: "RequestEntityTooLargeException",
    415: "UnsupportedDocumentEncodingException",
    429: "ThrottlingException",
    500: "InternalFailureException",
    503: "ServiceUnavailableException",
}
MAX_PUBLISH_BYTES = 128 * 1024  # AWS IoT's message size limit
LIST_PAGE_MAX = 100

Json = dict[str, Any]
# A route that answers (status, body, AWS error type) itself, given the method, the path,
# the body and the request's headers.
TypedRoute = Callable[[str, str, bytes, Mapping[str, str]], tuple[int, bytes, str | None]]


class ApiError(Exception):
    def __init__(self, status: int, message: str) -> None:
        super().__init__(message)
        self.status = status
        self.message = message


class DataPlane:
    """The request logic, separate from HTTP plumbing so it can be called directly too."""

    def __init__(
        self,
        shadows: ShadowService,
        publish: Callable[[str, bytes, int, bool], None],
        meter: Meter,
    ) -> None:
        self.shadows = shadows
        self._publish = publish
        self.meter = meter
        # Called with (topic, payload) after each publish (the simulator's command log).
        self.publish_observers: list[Callable[[str, bytes], None]] = []
        # Called with (topic, payload) before each publish is attempted.
        self.publish_starters: list[Callable[[str, bytes], None]] = []
        self.local_routes: dict[tuple[str, str], Callable[[Json], tuple[int, Json]]] = {}
        # GET paths answered with a redirect (the old dashboard, now the operator station).
        self.redirects: dict[str, str] = {}
        # What `GET /vahr/health` answers; the system adds what a client must adopt (the
        # robots' `sim_speed_factor`).
        self.health: Json = {"ok": True}
        # What the system still waits for before it can take a command (robots coming
        # online, the assistant's language model); while any, `GET /vahr/health` answers
        # 503 naming them. None: a bare stack, ready once it serves.
        self.awaiting: Callable[[], list[str]] | None = None
        # Path prefixes whose routes answer (status, body, AWS error type) themselves: the
        # IoT control plane's fleet-indexing calls (boto3's `iot` client), whose error
        # names the status alone does not tell. Each is given the request's headers too.
        self.typed_routes: dict[str, TypedRoute]
        self.typed_routes = {"/indices": FleetIndexApi(shadows.store.index).respond}

    def respond(
        self,
        method: str,
        raw_path: str,
        body: bytes,
        headers: Mapping[str, str] | None = None,
    ) -> tuple[int, bytes, str | None]:
        """`handle`, and the typed routes: (status, body, error type or None)."""
        path = urlsplit(raw_path).path
        for prefix, route in self.typed_routes.items():
            if path == prefix or path.startswith(prefix + "/"):
                return route(method, path, body, headers or {})
        status, payload = self.handle(method, raw_path, body)
        return status, payload, None

    def handle(self, method: str, raw_path: str, body: bytes) -> tuple[int, bytes]:
        """One request -> (status, response body)."""
        url = urlsplit(raw_path)
        query = {k: v[-1] for k, v in parse_qs(url.query, keep_blank_values=True).items()}
        parts = [unquote(p) for p in url.path.split("/") if p]
        try:
            if parts[:1] == ["vahr"]:
                return self._local(method, "/" + "/".join(parts), body, query)
            if len(parts) >= 2 and parts[0] == "topics":
                return self._publish_request(method, "/".join(parts[1:]), query, body)
            if len(parts) == 3 and parts[0] == "things" and parts[2] == "shadow":
                return self._shadow_request(method, parts[1], query.get("name"), body)
            if parts[:4] == ["api", "things", "shadow", "ListNamedShadowsForThing"] and (
                len(parts) == 5
            ):
                return self._list_named(method, parts[4], query)
            raise ApiError(404, f"No route for {method} {url.path}")
        except ShadowError as err:
            return _error(err.code, err.message)
        except ApiError as err:
            return _error(err.status, err.message)

    # -- publish ----------------------------------------------------------------------

    def _publish_request(
        self, method: str, topic: str, query: dict[str, str], body: bytes
    ) -> tuple[int, bytes]:
        if method != "POST":
            raise ApiError(405, f"{method} is not allowed on /topics")
        try:
            qos = int(query.get("qos", "0"))
        except ValueError:
            raise ApiError(400, "qos must be 0 or 1") from None
        if qos not in (0, 1):
            raise ApiError(400, "qos must be 0 or 1")
        retain = query.get("retain", "false").lower() == "true"
        if not topic or "+" in topic or "#" in topic:
            raise ApiError(400, f"'{topic}' is not a topic one can publish to")
        if len(body) > MAX_PUBLISH_BYTES:
            raise ApiError(413, "The payload exceeds the maximum size allowed")
        for starter in self.publish_starters:
            starter(topic, body)
        try:
            self._publish(topic, body, qos, retain)
        except VahrError as err:
            raise ApiError(503, str(err)) from err
        self.meter.message("http.publish", len(body))
        for observer in self.publish_observers:
            observer(topic, body)
        return 200, b""

    # -- shadows ----------------------------------------------------------------------

    def _shadow_request(
        self, method: str, thing: str, name: str | None, body: bytes
    ) -> tuple[int, bytes]:
        _check_names(thing, name)
        store = self.shadows.store
        if method == "GET":
            document = store.get(thing, name)
            document.pop("clientToken", None)
            encoded = _encode(document)
            self.meter.shadow("http.shadow.get", len(encoded))
            return 200, encoded
        if method == "POST":
            if len(body) > MAX_REQUEST_BYTES:
                raise ShadowError(413, "The payload exceeds the maximum size allowed")
            result = store.update(thing, name, body)
            self.meter.shadow("http.shadow.update", len(body))
            self.shadows.publish_update_result(thing, name, result)
            return 200, _encode(result.accepted)
        if method == "DELETE":
            deleted = store.delete(thing, name)
            self.meter.shadow("http.shadow.delete", len(_encode(deleted)))
            return 200, _encode(deleted)
        raise ApiError(405, f"{method} is not allowed on a shadow")

    def _list_named(self, method: str, thing: str, query: dict[str, str]) -> tuple[int, bytes]:
        if method != "GET":
            raise ApiError(405, f"{method} is not allowed here")
        _check_names(thing, None)
        try:
            page_size = int(query.get("pageSize", str(LIST_PAGE_MAX)))
            start = int(query.get("nextToken") or "0")
        except ValueError:
            raise ApiError(400, "pageSize and nextToken must be numbers") from None
        if not 1 <= page_size <= LIST_PAGE_MAX:
            raise ApiError(400, f"pageSize must be between 1 and {LIST_PAGE_MAX}")
        names = self.shadows.store.list_named(thing)
        page = names[start : start + page_size]
        body: Json = {"results": page, "timestamp": self.shadows.store.now()}
        if start + page_size < len(names):
            body["nextToken"] = str(start + page_size)
        self.meter.shadow("http.shadow.list", len(_encode(body)))
        return 200, _encode(body)

    # -- the local stack's own routes --------------------------------------------------

    def _local(
        self, method: str, path: str, body: bytes, query: dict[str, str] | None = None
    ) -> tuple[int, bytes]:
        if (method, path) == ("GET", "/vahr/health"):
            awaiting = self.awaiting() if self.awaiting is not None else []
            if awaiting:
                message = f"still starting: waiting for {'; '.join(awaiting)}"
                answer = {**self.health, "ok": False, "ready": False, "awaiting": awaiting}
                return 503, _encode({**answer, "code": 503, "message": message})
            return 200, _encode({**self.health, "ready": True})
        if (method, path) == ("GET", "/vahr/meter"):
            return 200, _encode(self.meter.snapshot())
        if (method, path) == ("POST", "/vahr/meter/reset"):
            self.meter.reset()
            return 200, _encode({"ok": True})
        route = self.local_routes.get((method, path))
        if route is None:
            raise ApiError(404, f"No route for {method} {path}")
        try:
            request = json.loads(body or b"{}")
        except (ValueError, RecursionError):
            raise ApiError(400, "Invalid JSON") from None
        if not isinstance(request, dict):
            raise ApiError(400, "the request body must be a JSON object")
        if method == "GET" and query:
            # A read's parameters are its query's (`GET /vahr/audit?after=10`).
            request = {**query, **request}
        status, response = route(request)
        return status, _encode(response)


def _check_names(thing: str, name: str | None) -> None:
    try:
        topics.shadow(thing, "get", name)
    except ValueError as err:
        raise ApiError(400, str(err)) from None


def _encode(body: object) -> bytes:
    return json.dumps(body, separators=(",", ":")).encode()


def _error(status: int, message: str) -> tuple[int, bytes]:
    return status, _encode({"code": status, "message": message})


class _Handler(QuietHandler):
    server: _Server

    # A client that stops sending mid-request holds a thread only this long.
    timeout = 30
    # Larger bodies are refused before they are read (AWS IoT's own limit is 128 KB).
    MAX_BODY_BYTES = MAX_PUBLISH_BYTES + 1024

    def _serve(self) -> None:
        refusal = self.server.guard.refusal(self.command, self.headers)
        if refusal is not None:
            # Refused before the body is read, so the connection cannot be used again.
            self.close_connection = True
            log.warning(
                "data plane refused %s %s: %s", self.command, self.path[:200], refusal.message
            )
            return self._answer(*_error(refusal.status, refusal.message))
        declared = self.headers.get("Content-Length")
        if declared is not None and not declared.strip().isdigit():
            # The body's end is unknown, so the connection cannot be used again.
            self.close_connection = True
            return self._answer(*_error(400, "Content-Length must be a whole number of bytes"))
        length = int(declared or 0)
        if length > self.MAX_BODY_BYTES:
            self.close_connection = True
            return self._answer(*_error(413, "The payload exceeds the maximum size allowed"))
        body = self.rfile.read(length) if length else b""
        target = self.server.dataplane.redirects.get(self.path.split("?", 1)[0])
        if target is not None and self.command == "GET":
            self.send_response(302)
            self.send_header("Location", target)
            self.send_header("Content-Length", "0")
            self.end_headers()
            return
        try:
            answer = self.server.dataplane.respond(
                self.command, self.path, body, dict(self.headers.items())
            )
            status, payload, error_type = answer
        except Exception:  # the server must answer even when a bug bites
            log.exception("data plane request %s %s failed", self.command, self.path)
            status, payload, error_type = (*_error(500, "Internal service failure"), None)
        self._answer(status, payload, error_type)

    def _answer(self, status: int, payload: bytes, error_type: str | None = None) -> None:
        self.send_response(status)
        self.send_header("Content-Type", "application/json")
        self.send_header("Content-Length", str(len(payload)))
        if status >= 400:
            error_type = error_type or ERROR_TYPES.get(status, "InvalidRequestException")
            self.send_header("x-amzn-ErrorType", error_type)
        if self.close_connection:
            self.send_header("Connection", "close")
        self.end_headers()
        if self.command != "HEAD":
            self.wfile.write(payload)

    def refuse(self, status: int, message: str) -> None:
        self._answer(*_error(status, message))

    def unknown_method(self) -> None:
        # Any method reaches the router, which answers 405 (or 404) in AWS's error shape.
        self._serve()


class _Server(QuietServer):
    what = "data-plane API"
    dataplane: DataPlane
    guard: BrowserGuard


class DataPlaneServer:
    """Serve a `DataPlane` on 127.0.0.1:port in a background thread; `stop()` joins it.

    `hosts` are names it answers to besides the loopback ones (a proxy's or a tunnel's)."""

    def __init__(
        self, dataplane: DataPlane, port: int, *, hosts: frozenset[str] = frozenset()
    ) -> None:
        ensure_free(port, "data-plane API")
        self._serving = ServerThread(_Server, _Handler, LOOPBACK, port)
        self._serving.server.dataplane = dataplane  # type: ignore[attr-defined]
        self._serving.server.guard = BrowserGuard(hosts)  # type: ignore[attr-defined]

    @property
    def port(self) -> int:
        return self._serving.port

    @property
    def url(self) -> str:
        return f"http://{LOOPBACK}:{self.port}"

    def start(self) -> DataPlaneServer:
        self._serving.start()
        return self

    def stop(self) -> None:
        self._serving.stop()

    def __enter__(self) -> DataPlaneServer:
        return self.start()

    def __exit__(self, *exc: object) -> None:
        self.stop()
