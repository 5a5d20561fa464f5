"""The lab client's fast path behaves exactly as paho's own client, byte for byte.

`vahr.plumbing.paho_fast_path.BatchingPahoClient` overrides paho's private read and write
methods and takes plain PUBLISH packets from its read buffer itself. Here one scripted peer
on 127.0.0.1 plays the broker for two clients in turn, paho's stock `Client` and the fast
one: it answers CONNECT with a CONNACK, reads the client's own publishes, and then sends
one fixed byte stream (messages at QoS 0 and 1, retained or not, with and without MQTT 5
properties, from empty to past one socket read, and acknowledgements of the client's
publishes in every form a broker may write them, refusals included), cut at the same
random places into segments sent apart, so packets straddle the client's reads. Both
clients must hand over the same messages and the same acknowledgements, and send back the
same bytes (their PUBACKs included). A real broker cannot replay one stream cut at chosen
places, which is why the peer is scripted.
"""

from __future__ import annotations

import random
import socket
import threading
import time
from typing import TYPE_CHECKING, Any

import paho.mqtt.client as paho
import pytest
from paho.mqtt.enums import CallbackAPIVersion, MQTTProtocolVersion

from tests.support.fault_injection_steps import wait_until
from vahr.plumbing.paho_fast_path import READ_CHUNK, BatchingPahoClient

if TYPE_CHECKING:
    from collections.abc import Callable, Iterator

CLIENT_ID = "fast-path-equivalence"
OWN_QOS1 = 6  # the client's QoS 1 publishes, packet ids 1..6, acknowledged in the stream
OWN_QOS0 = 2
TOPICS = ["vahr/robots/swarm0007/events", "$aws/things/swarm0007/shadow/update/accepted",
          "vahr/zöne/ß/events"]  # fmt: skip


def _varint(value: int) -> bytes:
    out = bytearray()
    while True:
        byte, value = value & 0x7F, value >> 7
        out.append(byte | (0x80 if value else 0))
        if not value:
            return bytes(out)


def _packet(header: int, body: bytes) -> bytes:
    return bytes([header]) + _varint(len(body)) + body


def _string(text: str) -> bytes:
    raw = text.encode()
    return len(raw).to_bytes(2, "big") + raw


def _publish(
    topic: str, payload: bytes, *, qos: int, retain: bool, mid: int, properties: bytes
) -> bytes:
    body = _string(topic) + (mid.to_bytes(2, "big") if qos else b"")
    body += _varint(len(properties)) + properties + payload
    return _packet(0x30 | qos << 1 | int(retain), body)


# MQTT 5 properties a publisher may set: message expiry (0x02), a user property (0x26).
EXPIRY = b"\x02" + (60).to_bytes(4, "big")
USER_PROPERTY = b"\x26" + _string("sent-by") + _string("test")
# The forms of PUBACK for packet ids 1..6: the short success form, success with its reason
# code, another success code (0x10, no matching subscribers), a refusal (0x87, not
# authorized) with an empty property length, success with a reason string, a refusal alone.
PUBACKS = [
    b"\x40\x02\x00\x01",
    b"\x40\x03\x00\x02\x00",
    b"\x40\x03\x00\x03\x10",
    b"\x40\x04\x00\x04\x87\x00",
    _packet(0x40, b"\x00\x05\x00" + _varint(7) + b"\x1f" + _string("fine")),
    b"\x40\x03\x00\x06\x87",
]


def _stream(rng: random.Random) -> tuple[bytes, int, int]:
    """The broker's bytes after the client's publishes: (stream, messages, QoS 1 ones)."""
    parts: list[bytes] = []
    qos1 = 0
    acks = list(PUBACKS)
    messages = 300
    for index in range(messages):
        qos = rng.choice((0, 1))
        qos1 += qos
        size = rng.choice((0, 1, 40, 330, 900, 20_000, READ_CHUNK + 17))
        payload = f"{index:04d}".encode() + rng.randbytes(size)
        properties = rng.choice((b"", b"", b"", EXPIRY, EXPIRY + USER_PROPERTY))
        parts.append(
            _publish(rng.choice(TOPICS), payload, qos=qos, retain=rng.random() < 0.2,
                     mid=index + 100, properties=properties)
        )  # fmt: skip
        if acks and index % 40 == 7:
            parts.append(acks.pop(0))
    parts.extend(acks)
    return b"".join(parts), messages, qos1


def _frames(data: bytes) -> list[bytes]:
    """Split what a client sent into whole MQTT packets."""
    found, at = [], 0
    while at < len(data):
        length, shift, cursor = 0, 0, at + 1
        while True:
            byte = data[cursor]
            length |= (byte & 0x7F) << shift
            cursor += 1
            if not byte & 0x80:
                break
            shift += 7
        found.append(data[at : cursor + length])
        at = cursor + length
    return found


class ScriptedBroker:
    """One connection on 127.0.0.1: CONNACK, then `stream` in the given segments once the
    client's own publishes arrived; records every byte the client sent."""

    def __init__(self, stream: bytes, cuts: list[int]) -> None:
        self._listener = socket.create_server(("127.0.0.1", 0))
        self.port = self._listener.getsockname()[1]
        self._stream, self._cuts = stream, cuts
        self.received = bytearray()
        self.closed = threading.Event()  # the client closed its end
        self._lock = threading.Lock()
        self._thread = threading.Thread(target=self._serve, daemon=True)
        self._thread.start()

    def frames(self) -> list[bytes]:
        with self._lock:
            return _frames(bytes(self.received))

    def _serve(self) -> None:
        connection, _ = self._listener.accept()
        with connection:
            reader = threading.Thread(target=self._read, args=(connection,), daemon=True)
            reader.start()
            wait_until(lambda: len(self.frames()) >= 1, 10)  # CONNECT
            connection.sendall(b"\x20\x03\x00\x00\x00")  # CONNACK, success, no properties
            wait_until(lambda: len(self.frames()) >= 1 + OWN_QOS1 + OWN_QOS0, 10)
            at = 0
            for index, cut in enumerate(self._cuts):
                connection.sendall(self._stream[at:cut])
                at = cut
                time.sleep(0.02 if index % 25 == 0 else 0.001)
            connection.sendall(self._stream[at:])
            reader.join(30)

    def _read(self, connection: socket.socket) -> None:
        while data := connection.recv(65536):
            with self._lock:
                self.received += data
        self.closed.set()

    def close(self) -> None:
        self._listener.close()
        self._thread.join(10)


def _run(
    make: Callable[[], paho.Client], stream: bytes, cuts: list[int], messages: int, qos1: int
) -> dict[str, Any]:
    """Connect a client to a scripted broker, let it take `stream`; what it saw and sent."""
    broker = ScriptedBroker(stream, cuts)
    taken: list[tuple[str, bytes, bool]] = []
    acknowledged: list[tuple[int, int]] = []
    disconnected: list[int] = []
    client = make()

    def on_message(_client: Any, _userdata: Any, message: paho.MQTTMessage) -> None:
        taken.append((message.topic, bytes(message.payload), bool(message.retain)))

    def on_publish(_client: Any, _userdata: Any, mid: int, reason: Any, _props: Any) -> None:
        acknowledged.append((mid, reason.value))

    client.on_message = on_message
    client.on_publish = on_publish
    client.on_disconnect = lambda _c, _u, _f, reason, _p: disconnected.append(reason.value)
    if isinstance(client, BatchingPahoClient):
        client.deliver = lambda topic, payload, retain: taken.append((topic, payload, retain))
    connected = threading.Event()
    client.on_connect = lambda *_: connected.set()
    client.connect("127.0.0.1", broker.port, keepalive=60)
    client.loop_start()
    try:
        assert connected.wait(10)
        for index in range(OWN_QOS1 + OWN_QOS0):
            client.publish(TOPICS[0], b"own %d" % index, qos=1 if index < OWN_QOS1 else 0)
        wait_until(lambda: len(taken) >= messages and len(acknowledged) >= OWN_QOS1 + OWN_QOS0, 30)
        # Every QoS 1 message of the stream is acknowledged back to the broker.
        puback_count = 1 + OWN_QOS1 + OWN_QOS0 + qos1
        wait_until(lambda: len(broker.frames()) >= puback_count, 10)
    finally:
        client.disconnect()
        client.loop_stop()
        closed = broker.closed.wait(5)
        broker.close()
    return {
        "messages": taken,
        "acknowledged": acknowledged,
        "sent": broker.frames(),
        "closed": closed,
        "disconnected": disconnected,
    }


def _stock() -> paho.Client:
    client = paho.Client(
        CallbackAPIVersion.VERSION2, client_id=CLIENT_ID, protocol=MQTTProtocolVersion.MQTTv5
    )
    client.max_inflight_messages_set(0)
    return client


def _fast() -> paho.Client:
    client = BatchingPahoClient(
        CallbackAPIVersion.VERSION2,
        client_id=CLIENT_ID,
        protocol=MQTTProtocolVersion.MQTTv5,
        window=OWN_QOS1 + OWN_QOS0,
    )
    client.max_inflight_messages_set(0)
    return client


@pytest.fixture(params=[11, 29], ids=lambda seed: f"seed{seed}")
def script(request: pytest.FixtureRequest) -> Iterator[tuple[bytes, list[int], int, int]]:
    rng = random.Random(request.param)
    stream, messages, qos1 = _stream(rng)
    cuts, at = [], 0
    while True:
        at += rng.choice((1, 2, 3, 5, 50, 700, 4096, READ_CHUNK + 5, 150_000))
        if at >= len(stream):
            break
        cuts.append(at)
    yield stream, cuts, messages, qos1


def test_the_fast_path_takes_and_acknowledges_what_paho_does(
    script: tuple[bytes, list[int], int, int],
) -> None:
    stream, cuts, messages, qos1 = script
    # Given one broker byte stream, cut at the same places for both clients
    # When paho's own client and the fast one each take it
    stock = _run(_stock, stream, cuts, messages, qos1)
    fast = _run(_fast, stream, cuts, messages, qos1)
    # Then they hand over the same messages, in the same order
    assert len(stock["messages"]) == messages
    assert fast["messages"] == stock["messages"]
    # And report the same acknowledgements of their own publishes (refusals included)
    assert sorted(stock["acknowledged"]) == [(1, 0), (2, 0), (3, 0x10), (4, 0x87), (5, 0),
                                             (6, 0x87), (7, 0), (8, 0)]  # fmt: skip
    assert fast["acknowledged"] == stock["acknowledged"]
    # And send the broker the same bytes: CONNECT, their publishes, a PUBACK for every QoS 1
    # message in arrival order, DISCONNECT
    assert sum(frame[0] == 0x40 for frame in stock["sent"]) == qos1
    assert stock["sent"][-1] == b"\xe0\x00"
    assert fast["sent"] == stock["sent"]
    # And, once asked to disconnect, close the connection and say so once
    assert stock["closed"] and stock["disconnected"] == [0]
    assert (fast["closed"], fast["disconnected"]) == (stock["closed"], stock["disconnected"])
