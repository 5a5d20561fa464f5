"""robot-agent footprint: idle CPU, resident memory, and command-to-shadow latency.

Starts a real mosquitto on loopback and a real `robot-agent run` process (sim backend),
then measures (1) the agent's CPU time while idle for `--idle-seconds` (target <= 0.5 % of
one core), (2) its resident memory (target <= 80 MB), and (3) the time from a test client
publishing a command to the same client receiving the agent's shadow update that
acknowledges it (target p50 <= 10 ms), for `ping` and for preempting `navigate` commands.
The latency includes two broker hops, so it is an upper bound on the agent's own time.
Finally (4) a swarm of `--swarm` robots in this process answers fleet-wide pings.
"""

from __future__ import annotations

import argparse
import json
import os
import socket
import subprocess
import sys
import tempfile
import threading
import time
import uuid
from pathlib import Path
from typing import Any

import paho.mqtt.client as paho
from _results import median, percentile, write_section
from paho.mqtt.enums import CallbackAPIVersion, MQTTProtocolVersion

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from vahr.plumbing.ports import free_port  # noqa: E402
from vahr.protocol import topics  # noqa: E402
from vahr.twin.broker import BrokerConfig, Mosquitto  # noqa: E402

THING = "placebot1"
CLOCK_TICKS = os.sysconf("SC_CLK_TCK")


def cpu_seconds(pid: int) -> float:
    fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / CLOCK_TICKS  # utime + stime


def rss_mb(pid: int) -> float:
    for line in Path(f"/proc/{pid}/status").read_text().splitlines():
        if line.startswith("VmRSS:"):
            return int(line.split()[1]) / 1024
    raise RuntimeError("no VmRSS")


class Probe:
    """A paho client (TCP_NODELAY) that times command -> acknowledging shadow update."""

    def __init__(self, port: int) -> None:
        self._client = paho.Client(
            CallbackAPIVersion.VERSION2,
            client_id=f"bench-{uuid.uuid4().hex[:8]}",
            protocol=MQTTProtocolVersion.MQTTv5,
        )
        self._client.on_socket_open = self._nodelay
        self._waiting: dict[str, threading.Event] = {}
        self._arrived: dict[str, float] = {}
        self._online = threading.Event()
        self._client.on_message = self._on_message
        self._client.connect("127.0.0.1", port)
        self._client.loop_start()
        self._client.subscribe(
            [(topics.shadow(THING, "update"), 1), (topics.robot_presence(THING), 1)]
        )

    @staticmethod
    def _nodelay(client: Any, userdata: Any, sock: Any) -> None:
        # paho does not set TCP_NODELAY; without it the probe itself would stall on Nagle.
        sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)

    def _on_message(self, client: Any, userdata: Any, message: paho.MQTTMessage) -> None:
        now = time.perf_counter()
        body = json.loads(message.payload)
        if message.topic.endswith("/presence"):
            if body.get("online"):
                self._online.set()
            return
        last = (body.get("state", {}).get("reported") or {}).get("last_command") or {}
        event = self._waiting.get(last.get("id", ""))
        if event is not None and not event.is_set():
            self._arrived[last["id"]] = now
            event.set()

    def wait_online(self, timeout_s: float) -> None:
        if not self._online.wait(timeout_s):
            raise RuntimeError("the agent did not come online")

    def round_trip(self, action: str, params: dict[str, Any]) -> float:
        command_id = uuid.uuid4().hex
        arrived = self._waiting[command_id] = threading.Event()
        payload = json.dumps(
            {
                "id": command_id,
                "action": action,
                "params": params,
                "issued_at": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime()),
                "source": "console",
            }
        )
        sent = time.perf_counter()
        self._client.publish(topics.robot_cmd(THING), payload, qos=1)
        if not arrived.wait(5):
            raise RuntimeError(f"no acknowledgment for {action} {command_id}")
        return (self._arrived.pop(command_id) - sent) * 1000

    def close(self) -> None:
        self._client.disconnect()
        self._client.loop_stop()


def swarm_fan_out(port: int, count: int, rounds: int) -> list[float]:
    """Fleet-wide ping to a swarm of `count` robots: ms until every robot's shadow acked it."""
    from tests.support.swarm_runner import SwarmThread

    acked: dict[str, set[str]] = {}
    done: dict[str, threading.Event] = {}
    arrived: dict[str, float] = {}

    def on_message(client: Any, userdata: Any, message: paho.MQTTMessage) -> None:
        body = json.loads(message.payload)
        last = (body.get("state", {}).get("reported") or {}).get("last_command") or {}
        command_id = last.get("id", "")
        if command_id in acked:
            acked[command_id].add(message.topic)
            if len(acked[command_id]) == count and not done[command_id].is_set():
                arrived[command_id] = time.perf_counter()
                done[command_id].set()

    client = paho.Client(CallbackAPIVersion.VERSION2, protocol=MQTTProtocolVersion.MQTTv5)
    client.on_socket_open = Probe._nodelay
    client.on_message = on_message
    client.connect("127.0.0.1", port)
    client.loop_start()
    client.subscribe(topics.ALL_SHADOW_UPDATES, qos=1)
    times: list[float] = []
    try:
        with SwarmThread(broker=f"mqtt://127.0.0.1:{port}", count=count):
            time.sleep(1)
            for _ in range(rounds):
                command_id = uuid.uuid4().hex
                acked[command_id], done[command_id] = set(), threading.Event()
                payload = json.dumps(
                    {
                        "id": command_id,
                        "action": "ping",
                        "params": {},
                        "source": "console",
                        "issued_at": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime()),
                    }
                )
                sent = time.perf_counter()
                client.publish(topics.FLEET_CMD, payload, qos=1)
                if not done[command_id].wait(30):
                    raise RuntimeError("the swarm did not acknowledge a fleet ping")
                times.append((arrived[command_id] - sent) * 1000)
    finally:
        client.disconnect()
        client.loop_stop()
    return times


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--idle-seconds", type=float, default=60.0)
    parser.add_argument("--commands", type=int, default=300, help="round trips per action")
    parser.add_argument("--swarm", type=int, default=100, help="robots in the swarm run")
    parser.add_argument("--swarm-rounds", type=int, default=20)
    parser.add_argument("--no-write", action="store_true", help="print, do not update docs")
    args = parser.parse_args()

    with tempfile.TemporaryDirectory(prefix="vahr-bench-") as tmp:
        broker = Mosquitto(BrokerConfig(state_dir=Path(tmp) / "broker", plain_port=free_port()))
        broker.start()
        agent = None
        probe = None
        try:
            port = broker.config.plain_port or 0
            probe = Probe(port)
            agent = subprocess.Popen(
                [
                    str(ROOT / ".venv" / "bin" / "robot-agent"),
                    "run",
                    "--thing",
                    THING,
                    "--broker",
                    f"mqtt://127.0.0.1:{port}",
                    "--state-dir",
                    str(Path(tmp) / "state"),
                    "--log-level",
                    "WARNING",
                ],
                stdin=subprocess.DEVNULL,
                stdout=subprocess.DEVNULL,
                stderr=subprocess.DEVNULL,
            )
            probe.wait_online(15)
            time.sleep(2)  # let start-up work (imports, first reports) settle
            cpu_before, wall_before = cpu_seconds(agent.pid), time.monotonic()
            time.sleep(args.idle_seconds)
            idle_cpu = cpu_seconds(agent.pid) - cpu_before
            idle_pct = 100 * idle_cpu / (time.monotonic() - wall_before)
            rss_idle = rss_mb(agent.pid)
            for _ in range(20):  # warm-up
                probe.round_trip("ping", {})
            pings = [probe.round_trip("ping", {}) for _ in range(args.commands)]
            zones = ["A", "B", "C", "D"]
            navigates = [
                probe.round_trip("navigate", {"zone": zones[i % 4]}) for i in range(args.commands)
            ]
            rss_busy = rss_mb(agent.pid)
            agent.terminate()
            if agent.wait(timeout=20) != 0:
                raise RuntimeError("robot-agent did not exit cleanly on SIGTERM")
            fan_out = swarm_fan_out(port, args.swarm, args.swarm_rounds)
        finally:
            if agent is not None and agent.poll() is None:
                agent.terminate()
                try:
                    agent.wait(timeout=20)
                except subprocess.TimeoutExpired:
                    agent.kill()
                    agent.wait(timeout=5)
            if probe is not None:
                probe.close()
            broker.stop()

    def row(name: str, values: list[float]) -> str:
        return (
            f"| {name} | {len(values)} | {median(values):.2f} | {percentile(values, 99):.2f} "
            f"| {max(values):.2f} |"
        )

    idle_cell = (
        f"{idle_pct:.3f} % of one core ({idle_cpu * 1000:.0f} ms CPU in {args.idle_seconds:g} s)"
    )
    swarm_row = (
        f"| {args.swarm} | {len(fan_out)} | {median(fan_out):.1f} "
        f"| {percentile(fan_out, 99):.1f} | {max(fan_out):.1f} |"
    )
    body = f"""
Idle: one `robot-agent run` (sim backend, plaintext loopback broker) doing nothing for
{args.idle_seconds:g} s; memory after idling and after the latency runs.

| measure | value | target |
| --- | --- | --- |
| idle CPU | {idle_cell} | <= 0.5 % |
| resident memory, idle | {rss_idle:.1f} MB | <= 80 MB |
| resident memory, after {2 * args.commands} commands | {rss_busy:.1f} MB | <= 80 MB |

Command published by a client -> the agent's acknowledging shadow update received by the
same client (two broker hops on loopback, QoS 1, sequential):

| command | n | p50 ms | p99 ms | max ms |
| --- | --- | --- | --- | --- |
{row("ping", pings)}
{row("navigate (each preempts the previous)", navigates)}

Swarm mode (`tests.support.swarm_runner`, one process, one connection): one publish on
`vahr/fleet/cmd` -> every robot's acknowledging shadow update received:

| robots | rounds | p50 ms | p99 ms | max ms |
| --- | --- | --- | --- | --- |
{swarm_row}
"""
    if args.no_write:
        print(body)
    else:
        write_section("agent_footprint", "robot-agent footprint", body)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
