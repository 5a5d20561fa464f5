"""Three ways to reach a Device Shadow service, behind one interface, so the same
compliance cases run over MQTT (local), over HTTP with boto3 (local data plane) and
against moto."""

from __future__ import annotations

import json
import queue
import uuid
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, Protocol

from botocore.exceptions import ClientError

from vahr.protocol import topics

if TYPE_CHECKING:
    from vahr.plumbing.mqtt import MqttClient

REPLY_TIMEOUT_S = 5.0


@dataclass(frozen=True)
class Reply:
    """What a caller observes: an HTTP-style status, the body, and the error name if any."""

    status: int
    body: dict[str, Any]
    error: str | None = None


STATUS_ERRORS = {
    400: "InvalidRequestException",
    404: "ResourceNotFoundException",
    409: "ConflictException",
    413: "RequestEntityTooLargeException",
    415: "UnsupportedDocumentEncodingException",
}


class Shadows(Protocol):
    kind: str

    def prepare(self, thing: str) -> None: ...
    def update(self, thing: str, payload: bytes, name: str | None = None) -> Reply: ...
    def get(self, thing: str, name: str | None = None) -> Reply: ...
    def delete(self, thing: str, name: str | None = None) -> Reply: ...
    def list_named(self, thing: str) -> list[str]: ...


class Boto3Shadows:
    """boto3's iot-data client; against the local data plane or inside moto."""

    def __init__(self, kind: str, client: Any, iot: Any | None = None) -> None:
        self.kind = kind
        self._client = client
        self._iot = iot

    def prepare(self, thing: str) -> None:
        if self._iot is not None:  # moto answers 404 for things that were never created
            self._iot.create_thing(thingName=thing)

    def _call(self, operation: str, **kwargs: Any) -> Reply:
        kwargs = {k: v for k, v in kwargs.items() if v is not None}
        try:
            response = getattr(self._client, operation)(**kwargs)
        except ClientError as err:
            status = err.response["ResponseMetadata"]["HTTPStatusCode"]
            body = {"code": status, "message": err.response["Error"].get("Message", "")}
            return Reply(status, body, err.response["Error"]["Code"])
        raw = response["payload"].read()
        return Reply(200, json.loads(raw) if raw else {})

    def update(self, thing: str, payload: bytes, name: str | None = None) -> Reply:
        return self._call("update_thing_shadow", thingName=thing, payload=payload, shadowName=name)

    def get(self, thing: str, name: str | None = None) -> Reply:
        return self._call("get_thing_shadow", thingName=thing, shadowName=name)

    def delete(self, thing: str, name: str | None = None) -> Reply:
        return self._call("delete_thing_shadow", thingName=thing, shadowName=name)

    def list_named(self, thing: str) -> list[str]:
        names: list[str] = self._client.list_named_shadows_for_thing(thingName=thing)["results"]
        return sorted(names)


@dataclass
class _Inbox:
    messages: queue.Queue[tuple[str, dict[str, Any]]] = field(default_factory=queue.Queue)


class MqttShadows:
    """The shadow MQTT API: publish a request, wait for `accepted` or `rejected`."""

    kind = "mqtt"

    def __init__(self, client: MqttClient) -> None:
        self._client = client
        self._inboxes: dict[str, _Inbox] = {}
        self.seen: list[tuple[str, dict[str, Any]]] = []

    def prepare(self, thing: str) -> None:
        inbox = self._inboxes.setdefault(thing, _Inbox())

        def on_message(topic: str, payload: bytes) -> None:
            parsed = topics.parse_shadow_topic(topic)
            if parsed is None or parsed[2] in ("update", "get", "delete"):
                return  # our own requests
            body = json.loads(payload)
            self.seen.append((topic, body))
            inbox.messages.put((topic, body))

        self._client.subscribe(topics.shadow_filter(thing), on_message)

    def _request(self, thing: str, name: str | None, operation: str, payload: bytes) -> Reply:
        inbox = self._inboxes[thing]
        self._client.publish(topics.shadow(thing, operation, name), payload)
        wanted = {
            topics.shadow(thing, f"{operation}/accepted", name): False,
            topics.shadow(thing, f"{operation}/rejected", name): True,
        }
        while True:
            topic, body = inbox.messages.get(timeout=REPLY_TIMEOUT_S)
            if topic in wanted:
                if wanted[topic]:
                    return Reply(body["code"], body, STATUS_ERRORS.get(body["code"]))
                return Reply(200, body)

    def update(self, thing: str, payload: bytes, name: str | None = None) -> Reply:
        return self._request(thing, name, "update", payload)

    def get(self, thing: str, name: str | None = None) -> Reply:
        return self._request(thing, name, "get", b"")

    def delete(self, thing: str, name: str | None = None) -> Reply:
        return self._request(thing, name, "delete", b"")

    def list_named(self, thing: str) -> list[str]:
        raise NotImplementedError("the MQTT API has no list operation")

    def drain(self, thing: str, topic: str) -> dict[str, Any]:
        """The next message on `topic` (e.g. update/delta) for `thing`."""
        inbox = self._inboxes[thing]
        while True:
            got, body = inbox.messages.get(timeout=REPLY_TIMEOUT_S)
            if got == topic:
                return body


def unique_thing() -> str:
    return f"robot-{uuid.uuid4().hex[:10]}"
