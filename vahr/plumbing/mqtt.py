"""The lab side's one MQTT client: the local services, the room assistant and the
experiment's recorder all connect through it (plaintext or mTLS), publish, subscribe with
callbacks and stop; every wait bounded. It implements the `Link` port. It and its faster
read and write path (`vahr.plumbing.paho_fast_path`, the one module that touches paho's
private methods) are the only importers of paho.

A session may be persistent (`session_expiry_s` > 0 with a fixed client id): while the
client is down the broker queues the QoS 1 messages it misses and delivers them when the
session resumes, which is what the experiment's recorder needs after a crash.
"""

from __future__ import annotations

import logging
import socket
import ssl
import threading
import uuid
from dataclasses import dataclass
from typing import TYPE_CHECKING

import paho.mqtt.client as paho
from paho.mqtt.enums import CallbackAPIVersion, MQTTProtocolVersion
from paho.mqtt.packettypes import PacketTypes
from paho.mqtt.properties import Properties

from vahr.errors import VahrError
from vahr.plumbing.paho_fast_path import BatchingPahoClient
from vahr.plumbing.ports import LOOPBACK
from vahr.protocol.link import topic_matches

if TYPE_CHECKING:
    from collections.abc import Callable

    from paho.mqtt.reasoncodes import ReasonCode

    from vahr.protocol.broker import ClientCredentials

log = logging.getLogger(__name__)

CONNECT_TIMEOUT_S = 10.0
PUBLISH_TIMEOUT_S = 5.0
# QoS 1 publishes of one client awaiting PUBACK at most. paho keeps no window of its own
# here (with one, it rescans every unacknowledged message on each PUBACK), and MQTT allows
# 65,535 at most (packet ids are 16 bits; past the broker's receive maximum mosquitto
# drops the client with "protocol error", as a swarm's start-up once made the shadow
# service do). A publisher past this bound waits for acknowledgments.
MAX_UNACKNOWLEDGED = 10_000
# How long a publisher waits for a slot: mosquitto busy with a swarm's burst acknowledges
# seconds late, and an answer given up on is lost.
WINDOW_TIMEOUT_S = 60.0
# Topics whose handlers are remembered; past this the memory starts again (a client that
# sees more distinct topics than this pays the matching again, nothing else).
ROUTE_CACHE_SIZE = 100_000


@dataclass(frozen=True, kw_only=True)
class MqttEndpoint:
    """Where and as whom to connect: a plaintext port, or an mTLS port with credentials."""

    port: int
    host: str = LOOPBACK
    credentials: ClientCredentials | None = None


class PublishDenied(VahrError):
    """The broker refused a publish (MQTT 5 PUBACK reason code >= 0x80)."""


class PublishUnconfirmed(VahrError):
    """No PUBACK came in time: the message is not sent again, but the broker may have it
    (the connection or the broker died after receiving it), so it may still be delivered."""


class MqttClient:
    """One MQTT 5 connection. Handlers run on paho's network thread: keep them short."""

    def __init__(
        self,
        endpoint: MqttEndpoint,
        *,
        client_id: str | None = None,
        session_expiry_s: int = 0,
        will: tuple[str, bytes] | None = None,
    ) -> None:
        """`will` is a (topic, payload) the broker publishes, retained, if this client goes
        away without saying goodbye (an empty payload clears what was retained there)."""
        self.endpoint = endpoint
        self.session_expiry_s = session_expiry_s
        self._client = BatchingPahoClient(
            CallbackAPIVersion.VERSION2,
            client_id=client_id or f"vahr-{uuid.uuid4().hex[:12]}",
            protocol=MQTTProtocolVersion.MQTTv5,
            window=MAX_UNACKNOWLEDGED,
        )
        # No bound of paho's own on QoS 1 publishes awaiting PUBACK (its default is 20): the
        # shadow service answers a swarm's burst with thousands of them, and with any bound
        # paho rescans every unacknowledged message on each PUBACK. The broker's receive
        # maximum (65,535) is the bound; mosquitto acknowledges within microseconds.
        self._client.max_inflight_messages_set(0)
        if will is not None:
            self._client.will_set(will[0], will[1], qos=1, retain=True)
        if endpoint.credentials is not None:
            creds = endpoint.credentials.check_files()
            try:
                context = ssl.create_default_context(
                    cafile=str(creds.ca_file) if creds.ca_file is not None else None
                )
                context.load_cert_chain(str(creds.cert_file), str(creds.key_file))
            except (OSError, ssl.SSLError) as err:
                raise VahrError(f"cannot load the certificate, key or CA: {err}") from err
            self._client.tls_set_context(context)
        # (filter, handler, whether retained messages reach it)
        self._handlers: list[tuple[str, Callable[[str, bytes], None], bool]] = []
        # The handlers of each topic seen, so a message costs one lookup, not one match per
        # subscription (paho's topic_matches_sub builds a matcher on every call).
        self._routes: dict[str, list[tuple[str, Callable[[str, bytes], None], bool]]] = {}
        self._connected_callbacks: list[Callable[[bool], None]] = []
        self._disconnected_callbacks: list[Callable[[str], None]] = []
        self._connected = threading.Event()
        self.connections = 0
        self._connect_error: str | None = None
        self._acks: dict[int, tuple[threading.Event, list[ReasonCode]]] = {}
        self._subacks: dict[int, tuple[threading.Event, list[ReasonCode]]] = {}
        self._early: dict[int, list[ReasonCode]] = {}
        self._ignored: set[int] = set()
        self._acks_lock = threading.Lock()
        self._client.on_connect = self._on_connect
        self._client.on_message = self._on_message
        self._client.deliver = self._deliver
        self._client.on_publish = self._on_publish
        self._client.on_socket_open = self._on_socket_open
        self._client.on_subscribe = self._on_subscribe
        self._client.on_disconnect = self._on_disconnect

    # -- lifecycle --------------------------------------------------------------------

    def connect(self) -> MqttClient:
        properties = None
        if self.session_expiry_s:
            properties = Properties(PacketTypes.CONNECT)
            properties.SessionExpiryInterval = self.session_expiry_s
        try:
            self._client.connect(
                self.endpoint.host,
                self.endpoint.port,
                keepalive=30,
                clean_start=not self.session_expiry_s,
                properties=properties,
            )
        except ssl.SSLError as err:
            raise VahrError(
                f"TLS handshake with {self.endpoint.host}:{self.endpoint.port} failed: "
                f"{err.reason or err}"
            ) from err
        except OSError as err:
            raise VahrError(
                f"cannot connect to the MQTT broker at {self.endpoint.host}:"
                f"{self.endpoint.port}: {err}"
            ) from err
        self._client.loop_start()
        if not self._connected.wait(CONNECT_TIMEOUT_S) or self._connect_error:
            self.stop()
            raise VahrError(
                f"the MQTT broker at {self.endpoint.host}:{self.endpoint.port} refused the "
                f"connection: {self._connect_error or 'timed out'}"
            )
        try:
            # Routes added before connecting: their handlers are already in place for what a
            # resumed session delivers at once; wait until every subscription holds.
            for topic_filter in dict.fromkeys(f for f, _, _ in self._handlers):
                self._subscribe_and_wait(topic_filter)
        except VahrError:
            self.stop()
            raise
        return self

    def stop(self) -> None:
        try:
            self._client.disconnect()
        finally:
            self._client.loop_stop()

    def __enter__(self) -> MqttClient:
        # Connecting twice would make paho reconnect under a caller's pending subscribe.
        return self if self._connected.is_set() else self.connect()

    def __exit__(self, *exc: object) -> None:
        self.stop()

    # -- messaging --------------------------------------------------------------------

    def subscribe(
        self,
        topic_filter: str,
        handler: Callable[[str, bytes], None],
        *,
        retained: bool = True,
    ) -> None:
        """Route messages matching `topic_filter` to `handler`; returns once SUBACKed.

        With `retained=False` the broker's retained messages (the past: a robot's last
        `delivered`, replayed on every subscription) do not reach `handler`.
        """
        self._handlers.append((topic_filter, handler, retained))
        self._routes = {}
        if self._connected.is_set():
            self._subscribe_and_wait(topic_filter)
        # Else `connect` subscribes it, before anything is published to this client.

    def _subscribe_and_wait(self, topic_filter: str) -> None:
        result, mid = self._client.subscribe(topic_filter, qos=1)
        if result != paho.MQTT_ERR_SUCCESS or mid is None:
            raise VahrError(f"cannot subscribe to {topic_filter}: {paho.error_string(result)}")
        waiter, _ = self._expect(self._subacks, mid)
        if not waiter.wait(CONNECT_TIMEOUT_S):
            raise VahrError(f"the MQTT broker did not acknowledge the subscription {topic_filter}")

    # -- the Link port (vahr.protocol.link) ---------------------------------------------

    def add_route(self, topic_filter: str, handler: Callable[[str, bytes], None]) -> None:
        self.subscribe(topic_filter, handler)

    def on_connected(self, callback: Callable[[bool], None]) -> None:
        self._connected_callbacks.append(callback)

    def on_disconnected(self, callback: Callable[[str], None]) -> None:
        self._disconnected_callbacks.append(callback)

    def publish(
        self, topic: str, payload: bytes, *, qos: int = 1, retain: bool = False, wait: bool = True
    ) -> None:
        """Publish; with `wait` and QoS 1, block until PUBACK and raise if it was refused.

        Without `wait` it still blocks while MAX_UNACKNOWLEDGED publishes await PUBACK,
        and a QoS 1 message published while disconnected is queued and sent after the
        client reconnects (a fire-and-forget notification, a shadow service's answer).

        A publish this raises for is never sent later: paho keeps a QoS 1 message it could
        not send (no connection) or that was not acknowledged, and sends it again after it
        reconnects, so a command the caller was told had failed would still reach a robot
        minutes later. Such a message is withdrawn from paho's queue before raising.
        """
        if wait and qos > 0 and not self._client.is_connected():
            raise VahrError(f"cannot publish to {topic}: not connected to the MQTT broker")
        if qos > 0 and not self._client.window.acquire(timeout=WINDOW_TIMEOUT_S):
            raise VahrError(
                f"the MQTT broker acknowledged none of {MAX_UNACKNOWLEDGED:,} publishes in "
                f"{WINDOW_TIMEOUT_S:g} s; not publishing to {topic}"
            )
        info = self._client.publish(topic, payload, qos=qos, retain=retain)
        if info.rc == paho.MQTT_ERR_NO_CONN and qos > 0 and not wait:
            # Queued: paho sends it after reconnecting, and its PUBACK frees the slot. The
            # caller asked not to wait, so this is not a failure; reported as one, the
            # data plane answered 500 for a shadow update it had stored (its notifications
            # go out here), and the robot ran a command its sender was told had failed.
            self._ignore(info.mid)
            return
        if info.rc != paho.MQTT_ERR_SUCCESS:
            if wait:
                self._withdraw(info.mid)
            raise VahrError(f"cannot publish to {topic}: {paho.error_string(info.rc)}")
        if qos == 0 or not wait:
            self._ignore(info.mid)
            return
        waiter, codes = self._expect(self._acks, info.mid)
        if not waiter.wait(PUBLISH_TIMEOUT_S):
            if self._withdraw(info.mid):
                raise PublishUnconfirmed(
                    f"the MQTT broker did not acknowledge a publish to {topic} within "
                    f"{PUBLISH_TIMEOUT_S:g} s; it will not be sent again (the broker may "
                    "still have received it)"
                )
            # Else it was acknowledged just now, between the timeout and the withdrawal.
            waiter.wait(1.0)
        if codes and codes[0].is_failure:
            raise PublishDenied(f"the MQTT broker refused a publish to {topic}: {codes[0]}")

    # Acknowledgments may arrive before the caller registers interest in them, and paho
    # calls back on its own thread while holding its own locks; so no lock of ours is ever
    # held across a call into paho, and early acknowledgments wait in `_early`.

    def _expect(
        self, table: dict[int, tuple[threading.Event, list[ReasonCode]]], mid: int
    ) -> tuple[threading.Event, list[ReasonCode]]:
        entry: tuple[threading.Event, list[ReasonCode]] = (threading.Event(), [])
        with self._acks_lock:
            early = self._early.pop(mid, None)
            if early is None:
                table[mid] = entry
        if early is not None:
            entry[1].extend(early)
            entry[0].set()
        return entry

    def _withdraw(self, mid: int) -> bool:
        """Drop message `mid` from paho's outgoing queue; False if it was acknowledged."""
        if not self._client.withdraw(mid):
            return False
        with self._acks_lock:
            self._acks.pop(mid, None)
        return True

    def _ignore(self, mid: int) -> None:
        with self._acks_lock:
            if self._early.pop(mid, None) is None:
                self._ignored.add(mid)

    def _acknowledged(
        self,
        table: dict[int, tuple[threading.Event, list[ReasonCode]]],
        mid: int,
        codes: list[ReasonCode],
    ) -> None:
        with self._acks_lock:
            if mid in self._ignored:
                self._ignored.discard(mid)
                return
            entry = table.pop(mid, None)
            if entry is None:
                self._early[mid] = codes
                return
        entry[1].extend(codes)
        entry[0].set()

    # -- paho callbacks ---------------------------------------------------------------

    def _on_socket_open(self, client, userdata, sock):  # type: ignore[no-untyped-def]
        self._client.forget_buffered()
        # paho does not set TCP_NODELAY; without it back-to-back publishes stall ~40 ms
        # (Nagle's algorithm waiting for the broker's delayed ACK).
        try:
            sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
        except OSError:
            log.debug("could not set TCP_NODELAY")

    def _on_connect(self, client, userdata, flags, reason_code, properties):  # type: ignore[no-untyped-def]
        if reason_code.is_failure:
            self._connect_error = str(reason_code)
        else:
            self.connections += 1
            if self.connections > 1:
                # Resubscribe after an automatic reconnect (`connect` does the first time).
                for topic_filter in dict.fromkeys(f for f, _, _ in self._handlers):
                    client.subscribe(topic_filter, qos=1)
            for callback in self._connected_callbacks:
                callback(bool(getattr(flags, "session_present", False)))
        self._connected.set()

    def _on_disconnect(self, client, userdata, flags, reason_code, properties):  # type: ignore[no-untyped-def]
        for callback in self._disconnected_callbacks:
            callback(str(reason_code))

    def _on_publish(self, client, userdata, mid, reason_code, properties):  # type: ignore[no-untyped-def]
        self._acknowledged(self._acks, mid, [reason_code])

    def _on_subscribe(self, client, userdata, mid, reason_codes, properties):  # type: ignore[no-untyped-def]
        self._acknowledged(self._subacks, mid, list(reason_codes))

    def _on_message(self, client, userdata, message):  # type: ignore[no-untyped-def]
        self._deliver(message.topic, bytes(message.payload), message.retain)

    def _deliver(self, topic: str, payload: bytes, retain: bool) -> None:
        """Run the handlers of `topic` (paho's network thread calls this, directly for a
        plain PUBLISH, through `_on_message` for anything else)."""
        # A local reference: a subscription made meanwhile starts a new cache, and what is
        # computed here from the old handlers must not land in it.
        cache = self._routes
        routes = cache.get(topic)
        if routes is None:
            routes = [
                (topic_filter, handler, retained)
                for topic_filter, handler, retained in self._handlers
                if topic_matches(topic_filter, topic)
            ]
            if len(cache) >= ROUTE_CACHE_SIZE:
                cache.clear()
            cache[topic] = routes
        for topic_filter, handler, retained in routes:
            if retain and not retained:
                continue
            try:
                handler(topic, payload)
            except Exception:  # a bad handler must not kill the network thread
                log.exception("handler for %s failed", topic_filter)


__all__ = ["MqttClient", "MqttEndpoint", "PublishDenied", "PublishUnconfirmed"]
