"""The local Device Shadow service: AWS IoT's shadow MQTT API over the local broker.

`ShadowService` turns requests on `$aws/things/{thing}/shadow[/name/{name}]/{update,get,
delete}` into `ShadowStore` calls and publishes the answers on `accepted`/`rejected`,
`update/delta` and `update/documents`, exactly where AWS publishes them. Updates made over
the HTTP data plane go through `publish_update_result`, so MQTT subscribers see them too
(AWS does the same; only rejections of HTTP requests stay off MQTT).

It also reproduces the cloud stack's presence rule: a robot's retained presence message
sets `reported.connected` in its classic shadow.
"""

from __future__ import annotations

import logging
from typing import TYPE_CHECKING

import msgspec

from vahr.local.shadow_store import ShadowError, ShadowStore, UpdateResult
from vahr.protocol import ProtocolError, decode_presence, topics

if TYPE_CHECKING:
    from collections.abc import Callable

    from vahr.local.meter import Meter
    from vahr.local.mqtt import MqttClient

log = logging.getLogger(__name__)

REQUEST_FILTERS = topics.shadow_request_filters()


def _encode(body: object) -> bytes:
    return msgspec.json.encode(body)


class ShadowService:
    """Serve the shadow topics of every thing from one `ShadowStore`."""

    def __init__(
        self,
        store: ShadowStore,
        publish: Callable[[str, bytes], None],
        meter: Meter | None = None,
    ) -> None:
        self.store = store
        self._publish = publish
        self._meter = meter

    def attach(self, client: MqttClient) -> None:
        """Subscribe `client` (holding the service identity) to requests and presence."""
        for topic_filter in REQUEST_FILTERS:
            client.subscribe(topic_filter, self.handle_request)
        client.subscribe(topics.ALL_PRESENCE, self.handle_presence)

    # -- requests ---------------------------------------------------------------------

    def handle_request(self, topic: str, payload: bytes) -> None:
        parsed = topics.parse_shadow_topic(topic)
        if parsed is None:
            return
        thing, name, operation = parsed
        if self._meter is not None:
            self._meter.shadow(f"mqtt.shadow.{operation}", len(payload))
        try:
            topics.check_thing(thing)
        except ValueError:
            log.warning("ignoring a shadow request for an invalid thing name: %s", topic)
            return
        try:
            if operation == "update":
                self.publish_update_result(thing, name, self.store.update(thing, name, payload))
            elif operation == "get":
                document = self.store.get(thing, name, payload)
                self._publish(topics.shadow(thing, "get/accepted", name), _encode(document))
            elif operation == "delete":
                body = self.store.delete(thing, name, payload)
                self._publish(topics.shadow(thing, "delete/accepted", name), _encode(body))
        except ShadowError as err:
            rejected = _encode(err.payload(self.store_time()))
            self._publish(topics.shadow(thing, f"{operation}/rejected", name), rejected)

    def store_time(self) -> int:
        return self.store.now()

    def publish_update_result(self, thing: str, name: str | None, result: UpdateResult) -> None:
        """Publish what AWS publishes after an accepted update, in AWS's order."""
        self._publish(topics.shadow(thing, "update/accepted", name), _encode(result.accepted))
        if result.delta is not None:
            self._publish(topics.shadow(thing, "update/delta", name), _encode(result.delta))
        self._publish(topics.shadow(thing, "update/documents", name), _encode(result.documents))

    # -- presence rule ----------------------------------------------------------------

    def handle_presence(self, topic: str, payload: bytes) -> None:
        parsed = topics.parse_robot_topic(topic)
        if parsed is None or parsed[1] != "presence":
            return
        thing = parsed[0]
        try:
            presence = decode_presence(payload)
        except ProtocolError as err:
            log.warning("ignoring malformed presence from %s: %s", thing, err)
            return
        request = _encode({"state": {"reported": {"connected": presence.online}}})
        try:
            self.publish_update_result(thing, None, self.store.update(thing, None, request))
        except ShadowError as err:  # only possible if the stored document is at its limit
            log.warning("presence of %s not recorded: %s", thing, err.message)
