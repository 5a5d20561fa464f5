"""The awsiotsdk (awscrt) MQTT 5 adapter of the `Link` port. awscrt is imported only here.

mTLS to AWS IoT Core or the local stack's mosquitto, or plaintext to a loopback broker in
development. The session is persistent (clean start false, a session expiry) so QoS 1
commands sent while the robot was away are delivered when it comes back; awscrt reconnects
with exponential backoff and jitter. The last will marks the robot offline (retained).
"""

from __future__ import annotations

import asyncio
import fcntl
import logging
import os
import socket
import threading
import time
from collections import deque
from concurrent import futures
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

from awscrt import io, mqtt5

from robot_agent.config import MqttSettings
from vahr.errors import VahrError
from vahr.protocol.link import topic_matches

if TYPE_CHECKING:
    from collections.abc import Callable
    from concurrent.futures import Future

    from vahr.protocol.broker import ClientCredentials

log = logging.getLogger(__name__)

SUBSCRIBE_CHUNK = 100
# Handlers run between two yields to the event loop when received messages are handled.
DISPATCH_CHUNK = 200


@dataclass(frozen=True, kw_only=True)
class Will:
    topic: str
    payload: bytes
    retain: bool = True


@dataclass(slots=True)
class _Received:
    """A received message waiting for its handlers; `next` is the first not yet run."""

    handlers: list[Callable[[str, bytes], None]]
    topic: str
    payload: bytes
    handle: mqtt5.PublishAcknowledgementControlHandle | None
    next: int = 0


@dataclass(frozen=True, kw_only=True)
class LinkSettings:
    client_id: str
    host: str
    port: int
    tls: ClientCredentials | None = None
    will: Will | None = None
    # The `mqtt` section of the agent's config: keep-alive, session expiry, reconnect delays.
    session: MqttSettings = MqttSettings()


class Mqtt5Link:
    """One MQTT 5 connection; see the module docstring. Start it with `await start()`."""

    def __init__(self, settings: LinkSettings, loop: asyncio.AbstractEventLoop) -> None:
        self.settings = settings
        self._loop = loop
        # Exact topics are looked up directly; only wildcard filters are matched one by one,
        # so a swarm of hundreds of robots on one link dispatches in constant time.
        self._exact: dict[str, list[Callable[[str, bytes], None]]] = {}
        self._wildcards: list[tuple[str, Callable[[str, bytes], None]]] = []
        self._filters: list[str] = []
        self._known_filters: set[str] = set()
        self._no_local: set[str] = set()
        self._connected_callbacks: list[Callable[[bool], None]] = []
        self._disconnected_callbacks: list[Callable[[str], None]] = []
        self._connected = threading.Event()
        # Set once the broker acknowledged every subscription of the current connection.
        self._subscribed = threading.Event()
        self._stopped = threading.Event()
        self._lock = threading.Lock()
        self._pending: set[Future[mqtt5.PublishCompletionData]] = set()
        # Received messages not yet handled, in arrival order (see `_drain`).
        self._inbox: deque[_Received] = deque()
        self._dispatching: _Received | None = None
        self._draining = False
        self.connections = 0
        self._stopping = False
        self._client = self._build_client()

    # -- the Link port ------------------------------------------------------------------

    def publish(self, topic: str, payload: bytes, *, retain: bool = False) -> None:
        packet = mqtt5.PublishPacket(
            topic=topic, payload=payload, qos=mqtt5.QoS.AT_LEAST_ONCE, retain=retain
        )
        future = self._client.publish(packet)
        with self._lock:
            self._pending.add(future)
        future.add_done_callback(self._published)

    def add_route(
        self, topic_filter: str, handler: Callable[[str, bytes], None], *, no_local: bool = False
    ) -> None:
        """`no_local`: the broker does not send back what this connection published itself
        (MQTT 5), e.g. a swarm's own robots' events, which it already knows."""
        if no_local:
            self._no_local.add(topic_filter)
        if "+" in topic_filter or "#" in topic_filter:
            self._wildcards.append((topic_filter, handler))
        else:
            self._exact.setdefault(topic_filter, []).append(handler)
        if topic_filter not in self._known_filters:
            self._known_filters.add(topic_filter)
            self._filters.append(topic_filter)
            if self._connected.is_set():
                self._subscribe([topic_filter])

    def on_connected(self, callback: Callable[[bool], None]) -> None:
        self._connected_callbacks.append(callback)

    def on_disconnected(self, callback: Callable[[str], None]) -> None:
        self._disconnected_callbacks.append(callback)

    # -- lifecycle ----------------------------------------------------------------------

    @property
    def connected(self) -> bool:
        return self._connected.is_set()

    async def start(self, timeout_s: float | None = None) -> None:
        """Start connecting; with `timeout_s`, wait that long for the first connection and
        the broker's acknowledgment of its subscriptions.

        Connected is not yet listening: a message published between the CONNACK and the
        SUBACK of a new session matches no subscription, and the broker drops it. A caller
        told the link has started may send at once (the soak lost its first command so).
        """
        self._client.start()
        if timeout_s is None:
            return
        deadline = time.monotonic() + timeout_s
        connected = await asyncio.to_thread(self._connected.wait, timeout_s)
        subscribed = connected and await asyncio.to_thread(
            self._subscribed.wait, max(0.0, deadline - time.monotonic())
        )
        if not subscribed:
            await self.stop()
            waited_for = "connect to" if not connected else "subscribe on"
            raise VahrError(
                f"could not {waited_for} {self.settings.host}:{self.settings.port} "
                f"within {timeout_s:g} s"
            )

    async def flush(self, timeout_s: float = 5.0) -> None:
        """Wait until every publish so far is acknowledged (or `timeout_s` passes)."""
        with self._lock:
            pending = list(self._pending)
        if not pending:
            return
        # Wait on awscrt's own futures from a worker thread rather than through asyncio
        # wrappers: cancelling a wrapper cancels the future it wraps, and awscrt completing
        # that future later raises InvalidStateError on its thread. Nothing here is ever
        # cancelled; `_published` logs each publish that fails, whenever it completes.
        await asyncio.to_thread(futures.wait, pending, timeout_s)

    async def stop(self, timeout_s: float = 5.0) -> None:
        """Disconnect normally (the broker discards the will) and wait until stopped."""
        self._stopping = True
        self._client.stop(
            mqtt5.DisconnectPacket(reason_code=mqtt5.DisconnectReasonCode.NORMAL_DISCONNECTION)
        )
        await asyncio.to_thread(self._stopped.wait, timeout_s)

    async def go_away(self, away_s: float, timeout_s: float = 5.0) -> None:
        """Drop the connection as a lost network would (the broker publishes the last will),
        stay away `away_s` wall seconds, then connect again (`vahr fault ... offline`)."""
        await self.flush(timeout_s)  # what was said before going away (the fault's answer)
        self._stopping = True
        self._stopped.clear()
        self._client.stop(
            mqtt5.DisconnectPacket(
                reason_code=mqtt5.DisconnectReasonCode.DISCONNECT_WITH_WILL_MESSAGE
            )
        )
        await asyncio.to_thread(self._stopped.wait, timeout_s)
        await asyncio.sleep(away_s)
        self._stopping = False
        self._client.start()

    # -- awscrt callbacks (on awscrt's threads) -----------------------------------------

    def _build_client(self) -> mqtt5.Client:
        s = self.settings
        will = None
        if s.will is not None:
            will = mqtt5.PublishPacket(
                topic=s.will.topic,
                payload=s.will.payload,
                qos=mqtt5.QoS.AT_LEAST_ONCE,
                retain=s.will.retain,
            )
        socket_options = io.SocketOptions()
        socket_options.connect_timeout_ms = s.session.connect_timeout_ms
        socket_options.domain = io.SocketDomain.IPv6 if ":" in s.host else io.SocketDomain.IPv4
        options = mqtt5.ClientOptions(
            host_name=s.host,
            port=s.port,
            bootstrap=io.ClientBootstrap.get_or_create_static_default(),
            socket_options=socket_options,
            tls_ctx=_tls_context(s.tls, s.port) if s.tls is not None else None,
            connect_options=mqtt5.ConnectPacket(
                client_id=s.client_id,
                keep_alive_interval_sec=s.session.keep_alive_s,
                session_expiry_interval_sec=s.session.session_expiry_s,
                will=will,
            ),
            # Rejoin even on the first connection of a new process, so commands queued by
            # the broker while the agent was down are delivered after a restart too.
            session_behavior=mqtt5.ClientSessionBehaviorType.REJOIN_ALWAYS,
            retry_jitter_mode=mqtt5.ExponentialBackoffJitterMode.FULL,
            min_reconnect_delay_ms=s.session.min_reconnect_delay_ms,
            max_reconnect_delay_ms=s.session.max_reconnect_delay_ms,
            ack_timeout_sec=30,
            on_publish_callback_fn=self._on_publish_received,
            on_lifecycle_event_connection_success_fn=self._on_lifecycle_connection_success,
            on_lifecycle_event_connection_failure_fn=self._on_lifecycle_connection_failure,
            on_lifecycle_event_disconnection_fn=self._on_lifecycle_disconnection,
            on_lifecycle_event_stopped_fn=self._on_lifecycle_stopped,
            # The username must stay the plain identity (mosquitto ACLs read it).
            disable_metrics=True,
        )
        return mqtt5.Client(options)

    def _subscribe(self, filters: list[str]) -> list[Future[mqtt5.SubackPacket]]:
        # Chunks keep each SUBSCRIBE packet small when a swarm subscribes thousands of topics.
        sent = []
        for start in range(0, len(filters), SUBSCRIBE_CHUNK):
            subscriptions = [
                mqtt5.Subscription(
                    topic_filter=f, qos=mqtt5.QoS.AT_LEAST_ONCE, no_local=f in self._no_local
                )
                for f in filters[start : start + SUBSCRIBE_CHUNK]
            ]
            future = self._client.subscribe(mqtt5.SubscribePacket(subscriptions=subscriptions))
            future.add_done_callback(self._on_suback)
            sent.append(future)
        return sent

    def _subscribe_all(self) -> None:
        """Subscribe to every filter again; `_subscribed` is set once all are acknowledged
        (or failed, which `_on_suback` logs)."""
        self._subscribed.clear()
        sent = self._subscribe(list(self._filters))
        if not sent:
            self._subscribed.set()
            return
        remaining = [len(sent)]

        def one_done(_future: Future[mqtt5.SubackPacket]) -> None:
            with self._lock:
                remaining[0] -= 1
                last = remaining[0] == 0
            if last:
                self._subscribed.set()

        for future in sent:
            future.add_done_callback(one_done)

    def _on_suback(self, future: Future[mqtt5.SubackPacket]) -> None:
        try:
            suback = future.result()
        except Exception as err:  # noqa: BLE001 - reported, the next connection retries
            log.warning("subscribe failed: %s", err)
            return
        refused = [c for c in suback.reason_codes if int(c) >= 0x80]
        if refused:
            log.warning("broker refused subscriptions: %s", [c.name for c in refused])

    def _published(self, future: Future[mqtt5.PublishCompletionData]) -> None:
        with self._lock:
            self._pending.discard(future)
        try:
            result = future.result()
        except Exception as err:  # noqa: BLE001 - a failed publish is logged, not fatal
            log.warning("publish failed: %s", err)
            return
        puback = result.puback
        if (
            puback is not None
            and puback.reason_code is not None
            and int(puback.reason_code) >= 0x80
        ):
            log.warning("broker refused a publish: %s", puback.reason_code.name)

    def _on_publish_received(self, data: mqtt5.PublishReceivedData) -> None:
        packet = data.publish_packet
        topic, payload = packet.topic, bytes(packet.payload or b"")
        handlers = list(self._exact.get(topic, ()))
        handlers += [h for f, h in self._wildcards if topic_matches(f, topic)]
        if not handlers:
            return
        # Acknowledge a QoS 1 message only after its handlers ran on the event loop (a
        # command's id is then on disk among the recent ids). awscrt would acknowledge it
        # when this callback returns, before the loop has seen it: a robot killed in
        # between lost the command, since the broker had its PUBACK and never sent it
        # again. Now the broker redelivers it when the robot is back, and it runs once.
        acquire = getattr(data, "acquire_publish_acknowledgement_control", None)
        handle = acquire() if acquire is not None else None  # None: awscrt before 0.36
        # Messages queue in arrival order for the event loop, which is woken once for a
        # burst rather than once per message.
        with self._lock:
            self._inbox.append(_Received(handlers, topic, payload, handle))
            if self._draining:
                return
            self._draining = True
        self._loop.call_soon_threadsafe(self._drain)

    def _drain(self) -> None:
        """Run the handlers of the queued messages in order, acknowledging each message
        after its last handler. After `DISPATCH_CHUNK` handlers it yields to the event loop
        and goes on later: a fleet command to a swarm of 10,000 robots has 10,000 handlers,
        which in one go held the loop (and every robot's timing) for seconds."""
        budget = DISPATCH_CHUNK
        while budget > 0:
            if self._dispatching is None:
                with self._lock:
                    if not self._inbox:
                        self._draining = False
                        return
                    self._dispatching = self._inbox.popleft()
            message = self._dispatching
            end = min(len(message.handlers), message.next + budget)
            _dispatch(message.handlers[message.next : end], message.topic, message.payload)
            budget -= end - message.next
            message.next = end
            if end == len(message.handlers):
                self._dispatching = None
                self._acknowledge(message.topic, message.handle)
        self._loop.call_soon(self._drain)

    def _acknowledge(
        self, topic: str, handle: mqtt5.PublishAcknowledgementControlHandle | None
    ) -> None:
        if handle is None:
            return
        try:
            self._client.invoke_publish_acknowledgement(handle)
        except Exception as err:  # noqa: BLE001 - the connection it came on is gone
            # The broker sends it again on the next connection; its id makes it a duplicate.
            log.debug("could not acknowledge a message on %s: %s", topic, err)

    def _on_lifecycle_connection_success(self, data: mqtt5.LifecycleConnectSuccessData) -> None:
        session_present = bool(data.connack_packet and data.connack_packet.session_present)
        self.connections += 1
        disable_nagle(self.settings.port)
        self._connected.set()
        log.info(
            "connected to %s:%s (session %s)",
            self.settings.host,
            self.settings.port,
            "resumed" if session_present else "new",
        )
        # Subscribing again is harmless when the session was resumed and required when
        # the broker lost it (a crash without persistence).
        self._subscribe_all()
        for callback in self._connected_callbacks:
            self._loop.call_soon_threadsafe(callback, session_present)

    def _on_lifecycle_connection_failure(self, data: mqtt5.LifecycleConnectFailureData) -> None:
        log.warning(
            "connection to %s:%s failed: %s", self.settings.host, self.settings.port, data.exception
        )

    def _on_lifecycle_disconnection(self, data: mqtt5.LifecycleDisconnectData) -> None:
        self._connected.clear()
        reason = str(data.exception) if data.exception else "disconnected"
        if self._stopping:
            log.info("disconnected on request")
        else:
            log.warning("disconnected: %s", reason)
        for callback in self._disconnected_callbacks:
            self._loop.call_soon_threadsafe(callback, reason)

    def _on_lifecycle_stopped(self, data: mqtt5.LifecycleStoppedData) -> None:
        self._stopped.set()


def disable_nagle(port: int) -> int:
    """Set TCP_NODELAY on this process's TCP connections to `port`; returns how many.

    awscrt's Python API has no TCP_NODELAY option (aws-c-io has one it does not expose
    yet), and without it the agent's writes after a command stall up to 40 ms on Nagle's
    algorithm waiting for the broker's delayed ACK, even with mosquitto's own
    `set_tcp_nodelay` (measured: docs/robot-agent.md). The connections are found through
    /proc (Linux): the socket inodes whose remote port is `port`, then this process's
    descriptors of those inodes. A duplicate descriptor shares the socket, so the option set
    on it holds for awscrt's descriptor; the file status flags (blocking mode) are restored
    after.
    """
    inodes = _connection_inodes(port)
    if not inodes:
        return 0
    changed = 0
    for entry in Path("/proc/self/fd").iterdir():
        try:
            if str(entry.readlink()) not in inodes:
                continue
            fd = int(entry.name)
            flags = fcntl.fcntl(fd, fcntl.F_GETFL)
            sock = socket.socket(fileno=os.dup(fd))
        except (OSError, ValueError):
            continue
        try:
            sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
            changed += 1
        except OSError:
            pass
        finally:
            sock.close()
            fcntl.fcntl(fd, fcntl.F_SETFL, flags)
    return changed


def _connection_inodes(port: int) -> set[str]:
    """`socket:[inode]` names of established TCP connections whose remote port is `port`."""
    found: set[str] = set()
    for table in (Path("/proc/net/tcp"), Path("/proc/net/tcp6")):
        try:
            lines = table.read_text().splitlines()[1:]
        except OSError:
            continue
        for line in lines:
            fields = line.split()
            if len(fields) > 9 and int(fields[2].rsplit(":", 1)[1], 16) == port:
                found.add(f"socket:[{fields[9]}]")
    return found


def _dispatch(handlers: list[Callable[[str, bytes], None]], topic: str, payload: bytes) -> None:
    for handler in handlers:
        try:
            handler(topic, payload)
        except Exception:
            # One robot's bug must not starve the others sharing this link.
            log.exception("handler for %s failed", topic)


def _tls_context(tls: ClientCredentials, port: int) -> io.ClientTlsContext:
    try:
        options = io.TlsContextOptions.create_client_with_mtls_from_path(
            str(tls.cert_file), str(tls.key_file)
        )
        if tls.ca_file is not None:
            options.override_default_trust_store_from_path(None, str(tls.ca_file))
        if port == 443 and io.is_alpn_available():
            # AWS IoT Core serves MQTT on 443 only with this ALPN protocol name.
            options.alpn_list = ["x-amzn-mqtt-ca"]
        # awscrt parses the PEM files only here; a file that is not one fails here too.
        return io.ClientTlsContext(options)
    except Exception as err:
        raise VahrError(f"cannot load the certificate, key or CA: {err}") from err
