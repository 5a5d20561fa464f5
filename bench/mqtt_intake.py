"""The lab's MQTT client against clients used through their public API: taking a burst.

A real mosquitto on loopback. A receiver subscribes with a persistent session and goes away;
a publisher queues `N` QoS 1 messages for it at the broker (robot events of about 250
bytes, as a fleet command's burst brings the station and the shadow service); the receiver
comes back and takes them all. Timed from reconnecting to the last message handed to the
handler: the receiving process's CPU per message and the wall time. Receivers:

- `MqttClient` (`vahr/plumbing/mqtt.py`: paho with the fast path of
  `vahr/plumbing/paho_fast_path.py`), as the lab runs;
- paho's own `Client`, through its public API only (`on_message`);
- the AWS CRT's MQTT 5 client (`awscrt.mqtt5.Client`, the robots' client, its I/O in C),
  through its public API (`on_publish_callback_fn`).

Each size and receiver `--runs` times, alternating; medians. `--tls` uses the local stack's
mTLS listener (the shadow service's identity) instead of plaintext.
Run: `.venv/bin/python bench/mqtt_intake.py [--sizes 2000 10000 40000] [--runs 3] [--tls]`.
"""

from __future__ import annotations

import argparse
import os
import socket
import sys
import tempfile
import threading
import time
from pathlib import Path
from typing import TYPE_CHECKING, Any

from _results import median, write_section

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import paho.mqtt.client as paho  # noqa: E402
from awscrt import io, mqtt5  # noqa: E402
from paho.mqtt.enums import CallbackAPIVersion, MQTTProtocolVersion  # noqa: E402
from paho.mqtt.packettypes import PacketTypes  # noqa: E402
from paho.mqtt.properties import Properties  # noqa: E402

from vahr.plumbing.mqtt import MqttClient, MqttEndpoint, PublishUnconfirmed  # noqa: E402
from vahr.plumbing.ports import free_port  # noqa: E402
from vahr.twin.stack import LocalStack, StackConfig  # noqa: E402

if TYPE_CHECKING:
    from collections.abc import Callable

TOPIC = "vahr/robots/swarm0001/events"
PAYLOAD = (
    b'{"event":"progress","thing":"swarm0001","at":"2026-11-28T22:00:00.000000Z",'
    b'"progress":0.5,"pose":{"x":1.25,"y":2.5,"theta":0.0},"command_id":"'
    + b"c" * 32
    + b'","zone":"A","detail":"'
    + b"d" * 60
    + b'"}'
)
SESSION_S = 600
TIMEOUT_S = 600.0


def cpu_s() -> float:
    usage = os.times()
    return usage.user + usage.system


class Receiver:
    """One client with a persistent session: `start` (re)connects it, `stop` leaves."""

    name = ""

    def __init__(self, endpoint: MqttEndpoint, on_message: Callable[[], None]) -> None:
        self.endpoint, self.on_message = endpoint, on_message

    def start(self) -> None:
        raise NotImplementedError

    def stop(self) -> None:
        raise NotImplementedError


class LabClient(Receiver):
    name = "the lab's `MqttClient` (paho and its fast path)"

    def start(self) -> None:
        # A new client each time (one `MqttClient` connects once), resuming the same session.
        self._client = MqttClient(self.endpoint, client_id="intake-lab", session_expiry_s=SESSION_S)
        self._client.subscribe(TOPIC, lambda _topic, _payload: self.on_message())
        self._client.connect()

    def stop(self) -> None:
        self._client.stop()


class PahoClient(Receiver):
    name = "paho's `Client`, public API"
    subscribed = False

    def start(self) -> None:
        client = paho.Client(
            CallbackAPIVersion.VERSION2,
            client_id="intake-paho",
            protocol=MQTTProtocolVersion.MQTTv5,
        )
        client.max_inflight_messages_set(0)
        client.on_message = lambda _c, _u, _message: self.on_message()
        # As the lab's client does (a public callback): no Nagle stall on its PUBACKs.
        client.on_socket_open = _no_delay
        if self.endpoint.credentials is not None:
            creds = self.endpoint.credentials
            client.tls_set(str(creds.ca_file), str(creds.cert_file), str(creds.key_file))
        subscribed = threading.Event()
        client.on_subscribe = lambda *_: subscribed.set()
        if not self.subscribed:
            # Once: the session keeps the subscription (a SUBACK asked for later would
            # wait behind the whole burst).
            client.on_connect = lambda c, *_: c.subscribe(TOPIC, qos=1)
        properties = Properties(PacketTypes.CONNECT)
        properties.SessionExpiryInterval = SESSION_S
        client.connect(
            self.endpoint.host, self.endpoint.port, clean_start=False, properties=properties
        )
        client.loop_start()
        if not self.subscribed and not subscribed.wait(10):
            raise RuntimeError("paho did not subscribe")
        self.subscribed = True
        self._client = client

    def stop(self) -> None:
        self._client.disconnect()
        self._client.loop_stop()


def _no_delay(_client: Any, _userdata: Any, sock: Any) -> None:
    sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)


class CrtClient(Receiver):
    name = "awscrt's `mqtt5.Client`, public API"

    subscribed = False
    # Every client made, kept until the end, so none is freed mid-run: awscrt 0.36 once
    # crashed the process (a segmentation fault) after a client had taken 40,000 messages
    # and the next one was made.
    made: list[mqtt5.Client] = []

    def start(self) -> None:
        # A new client each time, resuming the same session.
        connected, self._stopped = threading.Event(), threading.Event()
        tls = None
        if self.endpoint.credentials is not None:
            creds = self.endpoint.credentials
            options = io.TlsContextOptions.create_client_with_mtls_from_path(
                str(creds.cert_file), str(creds.key_file)
            )
            options.override_default_trust_store_from_path(None, str(creds.ca_file))
            tls = io.ClientTlsContext(options)
        self._client = mqtt5.Client(
            mqtt5.ClientOptions(
                host_name=self.endpoint.host,
                port=self.endpoint.port,
                bootstrap=io.ClientBootstrap.get_or_create_static_default(),
                tls_ctx=tls,
                connect_options=mqtt5.ConnectPacket(
                    client_id="intake-crt", session_expiry_interval_sec=SESSION_S
                ),
                session_behavior=mqtt5.ClientSessionBehaviorType.REJOIN_ALWAYS,
                on_publish_callback_fn=lambda _data: self.on_message(),
                on_lifecycle_event_connection_success_fn=lambda _data: connected.set(),
                on_lifecycle_event_stopped_fn=lambda _data: self._stopped.set(),
                disable_metrics=True,
            )
        )
        self.made.append(self._client)
        self._client.start()
        if not connected.wait(60):
            raise RuntimeError("awscrt did not connect")
        if not self.subscribed:
            subscription = mqtt5.Subscription(TOPIC, mqtt5.QoS.AT_LEAST_ONCE)
            self._client.subscribe(mqtt5.SubscribePacket([subscription])).result(10)
            self.subscribed = True

    def stop(self) -> None:
        self._client.stop()
        self._stopped.wait(30)


RECEIVERS = [LabClient, PahoClient, CrtClient]


def take_burst(
    receiver: Receiver, counter: dict[str, Any], endpoint: MqttEndpoint, size: int
) -> dict[str, float]:
    """Queue `size` messages for the (away) receiver, then time it taking them."""
    with MqttClient(endpoint) as publisher:
        for _ in range(size):
            publisher.publish(TOPIC, PAYLOAD, qos=1, wait=False)
        # PUBACKs come in order: once a marker is acknowledged, the broker holds the burst.
        # mosquitto saving a large queue to disk may hold its answers past one wait.
        for _ in range(20):
            try:
                publisher.publish(TOPIC + "/marker", b"", qos=1, wait=True)
                break
            except PublishUnconfirmed:
                continue
    time.sleep(1.0)
    counter["n"], counter["target"] = 0, size
    counter["done"].clear()
    before, started = cpu_s(), time.perf_counter()
    receiver.start()
    if not counter["done"].wait(TIMEOUT_S):
        raise RuntimeError(f"{receiver.name}: {counter['n']} of {size} messages arrived")
    wall = time.perf_counter() - started
    cpu = cpu_s() - before
    receiver.stop()
    return {"cpu_us": cpu / size * 1e6, "wall_ms": wall * 1000}


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--sizes", type=int, nargs="+", default=[2000, 10000, 40000])
    parser.add_argument("--runs", type=int, default=3)
    parser.add_argument("--tls", action="store_true", help="the mTLS listener, not plaintext")
    parser.add_argument("--no-write", action="store_true", help="print, do not update docs")
    args = parser.parse_args()
    results: dict[tuple[str, int], list[dict[str, float]]] = {}
    load_before = os.getloadavg()
    with tempfile.TemporaryDirectory(prefix="vahr-intake-") as state:
        config = StackConfig(
            state_dir=Path(state), mqtts_port=free_port(), mqtt_port=free_port(),
            api_port=free_port(),
        )  # fmt: skip
        with LocalStack(config) as stack:
            assert config.mqtt_port is not None
            endpoint = stack.service_endpoint() if args.tls else MqttEndpoint(port=config.mqtt_port)
            counter: dict[str, Any] = {"n": 0, "target": 0, "done": threading.Event()}
            lock = threading.Lock()

            def on_message() -> None:
                with lock:
                    counter["n"] += 1
                    if counter["n"] == counter["target"]:
                        counter["done"].set()

            receivers = [kind(endpoint, on_message) for kind in RECEIVERS]
            for receiver in receivers:  # subscribe each persistent session once
                counter["target"] = -1
                receiver.start()
                receiver.stop()
            for size in args.sizes:
                for run in range(args.runs):
                    order = receivers if run % 2 == 0 else list(reversed(receivers))
                    for receiver in order:
                        figures = take_burst(receiver, counter, endpoint, size)
                        results.setdefault((receiver.name, size), []).append(figures)
                        print(f"{size} {receiver.name}: {figures}", file=sys.stderr, flush=True)
    load_after = os.getloadavg()
    header = "| receiver | " + " | ".join(f"{size:,} messages" for size in args.sizes) + " |"
    rows = [header, "| --- |" + " --- |" * len(args.sizes)]
    for kind in RECEIVERS:
        cells = []
        for size in args.sizes:
            runs = results[(kind.name, size)]
            cpu = [r["cpu_us"] for r in runs]
            wall = median([r["wall_ms"] for r in runs])
            cells.append(f"{median(cpu):.1f} µs ({min(cpu):.1f}-{max(cpu):.1f}), {wall:,.0f} ms")
        rows.append(f"| {kind.name} | " + " | ".join(cells) + " |")
    table = "\n".join(rows)
    body = f"""
A burst of QoS 1 messages (about 250 bytes each) queued at mosquitto for a receiver with a
persistent session, taken when it comes back ({"mTLS" if args.tls else "plaintext"}, loopback);
the receiving process's CPU per message (median of {args.runs}, range) and the wall time until
the last message reached the handler. Load average (1, 5, 15 min) before
{"/".join(f"{v:.2f}" for v in load_before)}, after {"/".join(f"{v:.2f}" for v in load_after)}
on a machine shared with other work.

{table}

awscrt's cost per message grows with the burst: its MQTT 5 client inserts each PUBACK after
the PUBACKs already queued by walking all of them (`perf`: 91% of its time in
`s_aws_mqtt5_client_queue_puback` for 30,000 messages), so a fleet command's burst costs
the square of its length. Why the lab keeps paho's fast path, and the test that holds it to
paho's behaviour: docs/local.md, "The lab client's fast path".
"""
    if args.no_write:
        print(body)
    else:
        write_section("mqtt_intake", "The lab's MQTT client against public-API clients", body)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
