"""The local Device Shadow service: AWS IoT's shadow MQTT API over the local broker.

`ShadowService` turns requests on `$aws/things/{thing}/shadow[/name/{name}]/{update,get,
delete}` into `ShadowStore` calls and publishes the answers on `accepted`/`rejected`,
`update/delta` and `update/documents`, exactly where AWS publishes them. Updates made over
the HTTP data plane go through `publish_update_result`, so MQTT subscribers see them too
(AWS does the same; only rejections of HTTP requests stay off MQTT).

It also reproduces the cloud stack's presence rule: a robot's retained presence message
sets `reported.connected` in its classic shadow.

Every change the store makes to a classic shadow also updates its fleet index
(`store.index`, `vahr.twin.fleet_index`), which the data plane serves as AWS IoT fleet
indexing and the local stack queries in process.

Requests are served in bursts on a thread of the service's own (`start()`): the MQTT
client's network thread only queues what arrives, so it never waits on JSON work or on
disk. The worker takes everything queued (up to `BURST` requests), applies it in memory
in arrival order, commits the burst to SQLite in one transaction, and then publishes every
answer, each encoded once. Under light load a burst is one request and nothing waits;
under a swarm's load thousands of updates share one commit.
"""

from __future__ import annotations

import logging
import queue
import threading
from typing import TYPE_CHECKING

import msgspec

from vahr.protocol import ProtocolError, decode_presence, topics
from vahr.twin.shadow_store import ShadowError, ShadowStore, UpdateResult

if TYPE_CHECKING:
    from collections.abc import Callable

    from vahr.plumbing.mqtt import MqttClient
    from vahr.twin.meter import Meter

log = logging.getLogger(__name__)

REQUEST_FILTERS = topics.shadow_request_filters()
# The most requests applied before one commit: bounds how long the first of them waits.
BURST = 2000
STOP_TIMEOUT_S = 10.0


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
        # (handler, topic, payload); None asks the worker to finish.
        self._inbox: queue.SimpleQueue[tuple[Callable[[str, bytes], None], str, bytes] | None]
        self._inbox = queue.SimpleQueue()
        self._worker: threading.Thread | None = None
        # Answers of the burst being applied, published once it is committed.
        self._answers: list[tuple[str, bytes]] = []
        self.bursts = 0

    def attach(self, client: MqttClient) -> None:
        """Subscribe `client` (holding the service identity) to requests and presence, and
        start serving them."""
        self.start()
        for topic_filter in REQUEST_FILTERS:
            client.subscribe(topic_filter, self._queue_request)
        client.subscribe(topics.ALL_PRESENCE, self._queue_presence)

    def start(self) -> ShadowService:
        if self._worker is None:
            self._worker = threading.Thread(
                target=self._serve, name="vahr-shadow-service", daemon=True
            )
            self._worker.start()
        return self

    def stop(self, timeout_s: float = STOP_TIMEOUT_S) -> None:
        """Serve what is queued, then stop the worker."""
        worker, self._worker = self._worker, None
        if worker is not None:
            self._inbox.put(None)
            worker.join(timeout_s)

    def _queue_request(self, topic: str, payload: bytes) -> None:
        self._inbox.put((self.handle_request, topic, payload))

    def _queue_presence(self, topic: str, payload: bytes) -> None:
        self._inbox.put((self.handle_presence, topic, payload))

    def _serve(self) -> None:
        inbox = self._inbox
        while True:
            item = inbox.get()
            burst = []
            while item is not None:
                burst.append(item)
                if len(burst) >= BURST:
                    break
                try:
                    item = inbox.get_nowait()
                except queue.Empty:
                    break
            if burst:
                self._serve_burst(burst)
            if item is None:
                return

    def _serve_burst(self, burst: list[tuple[Callable[[str, bytes], None], str, bytes]]) -> None:
        answers: list[tuple[str, bytes]] = []
        self._answers = answers
        for handler, topic, payload in burst:
            try:
                handler(topic, payload)
            except Exception:  # one bad request must not stop the service
                log.exception("shadow request on %s failed", topic)
        try:
            self.store.commit()
        except Exception:
            # Nothing of this burst is announced as stored when it is not on disk; the
            # changes stay in memory and the next commit tries again.
            log.exception("could not write %d shadow changes to disk", len(answers))
            answers.clear()
        self._answers = []
        self.bursts += 1
        publish = self._publish
        for topic, body in answers:
            try:
                publish(topic, body)
            except Exception:
                log.exception("could not publish the answer on %s", topic)

    def _answer(self, topic: str, body: bytes) -> None:
        # On the worker, inside a burst, answers wait for the commit; elsewhere (the HTTP
        # data plane's threads, which commit before calling) they go out at once.
        if threading.current_thread() is self._worker:
            self._answers.append((topic, body))
        else:
            self._publish(topic, body)

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
        deferred = threading.current_thread() is self._worker
        try:
            if operation == "update":
                result = self.store.update(thing, name, payload, commit=not deferred)
                self.publish_update_result(thing, name, result)
            elif operation == "get":
                document = self.store.get(thing, name, payload)
                self._answer(topics.shadow(thing, "get/accepted", name), _encode(document))
            elif operation == "delete":
                body = self.store.delete(thing, name, payload, commit=not deferred)
                self._answer(topics.shadow(thing, "delete/accepted", name), _encode(body))
        except ShadowError as err:
            rejected = _encode(err.payload(self.store_time()))
            self._answer(topics.shadow(thing, f"{operation}/rejected", name), rejected)

    def store_time(self) -> int:
        return self.store.now()

    def publish_update_result(self, thing: str, name: str | None, result: UpdateResult) -> None:
        """Publish what AWS publishes after an accepted update, in AWS's order."""
        self._answer(topics.shadow(thing, "update/accepted", name), _encode(result.accepted))
        if result.delta is not None:
            self._answer(topics.shadow(thing, "update/delta", name), _encode(result.delta))
        self._answer(topics.shadow(thing, "update/documents", name), _encode(result.documents))

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
        deferred = threading.current_thread() is self._worker
        try:
            result = self.store.update(thing, None, request, commit=not deferred)
            self.publish_update_result(thing, None, result)
        except ShadowError as err:  # only possible if the stored document is at its limit
            log.warning("presence of %s not recorded: %s", thing, err.message)
