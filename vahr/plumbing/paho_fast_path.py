"""The one place that reaches into paho-mqtt's private methods: a faster read and write path.

`BatchingPahoClient` is paho 2.2's `Client` with its socket reads and writes done in chunks,
plain PUBLISH packets (MQTT 5, QoS 0 or 1, no properties) handed from the read buffer to a
`deliver` callable, and a window of QoS 1 publishes awaiting PUBACK. Everything else is
paho's own behaviour. `vahr.plumbing.mqtt.MqttClient` is its only user.

Why it exists (`bench/mqtt_intake.py`; docs/local.md, "The lab client's fast path"): taking
a burst of QoS 1 messages, paho through its public API spends 120-250 µs of CPU a message (a
`select`, several `recv` calls and a wake-up write per packet), this path 15-30 µs. The AWS
CRT's MQTT 5 client (`awscrt.mqtt5`, public API, its I/O in C) was measured in its place:
about 40 µs a message in a burst of 2,000 and about 1,000 µs in a burst of 40,000, because
awscrt 0.36 inserts each PUBACK into its operation queue by walking every PUBACK already
queued there. So the fast path stays, held to paho's own behaviour by
`tests/integration/local/test_paho_fast_path.py`, which feeds one byte stream (cut at random
places) to this client and to paho's stock client and asserts the same messages and the same
bytes back (acknowledgements included). The overridden methods are private, which is why
paho is pinned exactly in requirements.txt: a new paho release is taken only when that test
passes against it.
"""

from __future__ import annotations

import contextlib
import logging
import threading
from typing import TYPE_CHECKING, Any

import paho.mqtt.client as paho
from paho.mqtt.enums import MQTTErrorCode, MQTTProtocolVersion
from paho.mqtt.packettypes import PacketTypes
from paho.mqtt.properties import Properties
from paho.mqtt.reasoncodes import ReasonCode

if TYPE_CHECKING:
    from collections.abc import Callable

log = logging.getLogger(__name__)

# Bytes taken from the socket at once, and the most packets handled per wake-up.
READ_CHUNK = 64 * 1024
READ_BURST = 1000
WRITE_CHUNK = 64 * 1024


class BatchingPahoClient(paho.Client):
    """paho's client, reading and writing in chunks rather than packet by packet.

    paho 2.2 reads each packet with three or more `recv` calls (type, length, body), handles
    at most one packet per `select` when nothing of its own is in flight, writes each packet
    with its own `send`, and wakes its network thread with one more `send` per packet
    queued. At a swarm's rate (the shadow service takes 20,000 requests for one fleet
    command to 10,000 robots) those system calls were most of its time. Here a read takes
    up to `READ_CHUNK` bytes and packets are served from that buffer, all buffered packets
    are handled per wake-up, queued packets go out in one `send`, and the thread is woken
    only when its queue was empty, and plain PUBLISH packets go from the buffer straight to
    the client's handlers (`_deliver_plain`). The MQTT behaviour is paho's own; the
    overridden methods are paho's private ones, which is why paho is pinned exactly.
    """

    def __init__(self, *args: object, window: int, **kwargs: object) -> None:
        super().__init__(*args, **kwargs)  # type: ignore[arg-type]
        self._inbound = bytearray()
        # Where plain PUBLISH packets go straight from the buffer (`_deliver_plain`):
        # (topic, payload, retain). Unset, every packet takes paho's way.
        self.deliver: Callable[[str, bytes, bool], None] | None = None
        # QoS 1 publishes sent and not yet acknowledged: a publisher takes a slot before
        # publishing, each PUBACK gives one back (`window` slots; see `MqttClient`).
        self.window = threading.BoundedSemaphore(window)

    def _do_on_publish(self, mid: int, reason_code: Any, properties: Any) -> MQTTErrorCode:
        # Called for each PUBACK of a QoS 1 publish (a QoS 0 one never takes a slot).
        with contextlib.suppress(ValueError):  # released more often than taken: ignore
            self.window.release()
        return super()._do_on_publish(mid, reason_code, properties)  # type: ignore[no-any-return]

    def forget_buffered(self) -> None:
        """A new socket starts with nothing buffered from the old one."""
        self._inbound.clear()

    def withdraw(self, mid: int) -> bool:
        """Drop message `mid` from paho's outgoing queue, so it is never sent again, and
        free its slot in the window; False if it was acknowledged meanwhile.

        paho 2.2 has no public way to cancel a publish; its queue and counter are guarded by
        its own mutex, which is taken here exactly as paho takes it.
        """
        with self._out_message_mutex:
            message = self._out_messages.pop(mid, None)
            if message is not None and message.state == paho.mqtt_ms_wait_for_puback:
                self._inflight_messages -= 1
        if message is None:
            return False
        if message.qos > 0:
            with contextlib.suppress(ValueError):  # released more often than taken: ignore
                self.window.release()
        return True

    def _sock_recv(self, bufsize: int) -> bytes:
        buffered = self._inbound
        if not buffered:
            data = super()._sock_recv(READ_CHUNK)  # BlockingIOError when there is none
            if not data:
                return b""
            buffered += data
        chunk = bytes(buffered[:bufsize])
        del buffered[:bufsize]
        return chunk

    def loop_read(self, max_packets: int = 1) -> MQTTErrorCode:
        for _ in range(READ_BURST):
            if self._sock is None:
                return MQTTErrorCode.MQTT_ERR_NO_CONN
            if self._in_packet["command"] == 0 and self.deliver is not None:
                # Between packets: plain PUBLISHes are taken from the buffer here, and
                # paho reads only what is left at the head (another packet, or a part).
                if not self._inbound:
                    try:
                        data = super()._sock_recv(READ_CHUNK)
                    except BlockingIOError:
                        return MQTTErrorCode.MQTT_ERR_SUCCESS
                    except OSError as err:
                        self._easy_log(paho.MQTT_LOG_ERR, "failed to receive on socket: %s", err)
                        return self._loop_rc_handle(MQTTErrorCode.MQTT_ERR_CONN_LOST)  # type: ignore[no-any-return]
                    if not data:
                        return self._loop_rc_handle(MQTTErrorCode.MQTT_ERR_CONN_LOST)  # type: ignore[no-any-return]
                    self._inbound += data
                rc = self._deliver_plain()
                if rc > 0:
                    return self._loop_rc_handle(rc)  # type: ignore[no-any-return]
                if not self._inbound:
                    continue
            rc = self._packet_read()
            if rc > 0:
                return self._loop_rc_handle(rc)  # type: ignore[no-any-return]
            if rc == MQTTErrorCode.MQTT_ERR_AGAIN:
                return MQTTErrorCode.MQTT_ERR_SUCCESS
        if self._inbound and self._sockpairW is not None:
            # More is buffered but the socket may have nothing new: wake `select` at once.
            with contextlib.suppress(BlockingIOError):
                self._sockpairW.send(b"0")
        return MQTTErrorCode.MQTT_ERR_SUCCESS

    def _deliver_plain(self) -> MQTTErrorCode:
        """Hand every whole plain PUBLISH at the head of the buffer to `deliver`.

        Plain: MQTT 5, QoS 0 or 1, no properties, a UTF-8 topic: every message of the
        robots, the shadow service and the station. paho's own way costs a packet state
        machine, an `MQTTMessage` and two locks a message, which was half of what the
        station spent per message in a 10,000-robot fleet command's burst. Anything else
        (another packet type, properties, QoS 2, a packet not whole yet) stays in the
        buffer for paho, so its behaviour is paho's own.
        """
        buffered = self._inbound
        deliver = self.deliver
        size = len(buffered)
        at = 0
        rc = MQTTErrorCode.MQTT_ERR_SUCCESS
        taken = 0
        while at + 2 <= size and deliver is not None:
            header = buffered[at]
            if header >> 4 != 3 or self._protocol != MQTTProtocolVersion.MQTTv5:
                break
            # The remaining length: one to four bytes, seven bits each, low first.
            length = shift = 0
            cursor = at + 1
            while cursor < size and shift <= 21:
                byte = buffered[cursor]
                length |= (byte & 0x7F) << shift
                cursor += 1
                if not byte & 0x80:
                    break
                shift += 7
            else:
                break  # the length itself is not whole yet (or is malformed: paho says)
            end = cursor + length
            qos = (header >> 1) & 0x03
            if end > size or qos > 1 or length < 3:
                break
            topic_end = cursor + 2 + ((buffered[cursor] << 8) | buffered[cursor + 1])
            props = topic_end + 2 if qos else topic_end
            if props >= end or buffered[props] != 0:
                break
            try:
                topic = buffered[cursor + 2 : topic_end].decode()
            except UnicodeDecodeError:
                break
            payload = bytes(buffered[props + 1 : end])
            mid = (buffered[topic_end] << 8) | buffered[topic_end + 1] if qos else 0
            at = end
            taken += 1
            deliver(topic, payload, bool(header & 0x01))
            if qos == 1 and not self._manual_ack:
                rc = self._send_puback(mid)
                if rc > 0:
                    break
        if at:
            del buffered[:at]
        if taken:
            now = paho.time_func()
            with self._msgtime_mutex:
                self._last_bytes_received = now
        return rc

    def _packet_queue(
        self,
        command: int,
        packet: bytes | bytearray,
        mid: int,
        qos: int,
        info: paho.MQTTMessageInfo | None = None,
    ) -> MQTTErrorCode:
        if self._thread is not None and self._out_packet:
            # The network thread was woken for the packets already queued and writes them
            # all, this one included.
            self._out_packet.append(
                {"command": command, "mid": mid, "qos": qos, "pos": 0,
                 "to_process": len(packet), "packet": packet, "info": info}
            )  # fmt: skip
            return MQTTErrorCode.MQTT_ERR_SUCCESS
        return super()._packet_queue(command, packet, mid, qos, info)

    def _packet_write(self) -> MQTTErrorCode:
        # Other threads append to the queue meanwhile: it is only ever read by index and
        # popped from the left here (paho's own discipline), never iterated or cleared.
        queued = self._out_packet
        while queued:
            batch = []
            size = 0
            for index in range(len(queued)):
                packet = queued[index]
                batch.append(packet)
                size += packet["to_process"]
                if size >= WRITE_CHUNK or _is_disconnect(packet):
                    break  # nothing is sent after a DISCONNECT (paho closes the socket)
            data = b"".join(bytes(p["packet"][p["pos"] :]) for p in batch)
            try:
                written = self._sock_send(data)
            except (AttributeError, ValueError):
                return MQTTErrorCode.MQTT_ERR_SUCCESS
            except BlockingIOError:
                return MQTTErrorCode.MQTT_ERR_AGAIN
            except OSError as err:
                self._easy_log(paho.MQTT_LOG_ERR, "failed to send on socket: %s", err)
                return MQTTErrorCode.MQTT_ERR_CONN_LOST
            for packet in batch:
                if written <= 0:
                    break
                taken = min(written, packet["to_process"])
                packet["to_process"] -= taken
                packet["pos"] += taken
                written -= taken
                if packet["to_process"] == 0:
                    queued.popleft()
                    if _is_qos0_publish(packet):
                        self._qos0_published(packet)
                    elif _is_disconnect(packet):
                        self._disconnect_written()
                        return MQTTErrorCode.MQTT_ERR_SUCCESS
            if queued and queued[0]["pos"] > 0:
                return MQTTErrorCode.MQTT_ERR_AGAIN  # the socket took only part of it
        with self._msgtime_mutex:
            self._last_msg_out = paho.time_func()
        return MQTTErrorCode.MQTT_ERR_SUCCESS

    def _disconnect_written(self) -> None:
        """What paho does once its DISCONNECT is written: on_disconnect, close the socket."""
        with self._msgtime_mutex:
            self._last_msg_out = paho.time_func()
        self._do_on_disconnect(packet_from_broker=False, v1_rc=MQTTErrorCode.MQTT_ERR_SUCCESS)
        self._sock_close()
        # Disconnected only when the client asked to be (as paho decides it).
        if self._state == paho._ConnectionState.MQTT_CS_DISCONNECTING:
            self._state = paho._ConnectionState.MQTT_CS_DISCONNECTED

    def _handle_pubackcomp(self, cmd: Any) -> MQTTErrorCode:
        # A plain success PUBACK (packet id, then no reason code or reason 0, no
        # properties) is most of what a busy publisher reads; paho builds a reason code and
        # a property set for each. Those two are shared here; anything else is paho's.
        packet = self._in_packet["packet"]
        if cmd == "PUBACK" and (len(packet) == 2 or (len(packet) == 3 and packet[2] == 0)):
            mid = (packet[0] << 8) | packet[1]
            with self._out_message_mutex:
                if mid in self._out_messages:
                    return self._do_on_publish(mid, _PUBACK_SUCCESS, _NO_PROPERTIES)  # type: ignore[no-any-return]
            return MQTTErrorCode.MQTT_ERR_SUCCESS
        return super()._handle_pubackcomp(cmd)  # type: ignore[no-any-return]

    def _qos0_published(self, packet: Any) -> None:
        """What paho does once a QoS 0 publish is written: it counts as published."""
        with self._callback_mutex:
            on_publish = self.on_publish
        if on_publish is not None:
            with self._in_callback_mutex:
                try:
                    on_publish(  # type: ignore[call-arg]
                        self,
                        self._userdata,
                        packet["mid"],
                        ReasonCode(PacketTypes.PUBACK),
                        Properties(PacketTypes.PUBACK),
                    )
                except Exception:
                    log.exception("on_publish failed")
        if packet["info"] is not None:
            packet["info"]._set_as_published()


# Read-only: handed to on_publish for every plain PUBACK (see `_handle_pubackcomp`).
_PUBACK_SUCCESS = ReasonCode(PacketTypes.PUBACK)
_NO_PROPERTIES = Properties(PacketTypes.PUBACK)


def _is_qos0_publish(packet: Any) -> bool:
    return bool((packet["command"] & 0xF0) == paho.PUBLISH and packet["qos"] == 0)


def _is_disconnect(packet: Any) -> bool:
    return bool((packet["command"] & 0xF0) == paho.DISCONNECT)


__all__ = ["BatchingPahoClient"]
