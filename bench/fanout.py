"""Fan-out: one fleet command to 10, 100 and 1,000 robots until every shadow acknowledged.

The robots run in swarm mode (many agent cores on one event loop and one MQTT connection,
`tests.support.swarm`) against the local stack. The command goes out as the skill sends it,
one iot-data Publish to `vahr/fleet/cmd` through the local data plane; the clock stops when
the shadow service has accepted, for every robot, a reported `last_command.id` equal to the
command's id (seen on `update/accepted`, which the shadow service publishes after storing).
Run: `.venv/bin/python bench/fanout.py [--sizes 10 100 1000] [--runs 3]`.
"""

from __future__ import annotations

import argparse
import json
import multiprocessing
import os
import sys
import tempfile
import threading
import time
from pathlib import Path
from typing import Any

from _results import median, write_section

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import boto3  # noqa: E402

from vahr.local.mqtt import MqttClient  # noqa: E402
from vahr.local.ports import free_port  # noqa: E402
from vahr.local.stack import LocalStack, StackConfig  # noqa: E402
from vahr.protocol import encode, new_command, topics  # noqa: E402

ACK_TIMEOUT_S = 30.0


class Acknowledgments:
    """Which robots' stored shadows name the awaited command id."""

    def __init__(self, expected: int) -> None:
        self.expected = expected
        self.command_id = ""
        self.acked: set[str] = set()
        self.done = threading.Event()
        self.first_at = 0.0
        self.last_at = 0.0
        self._lock = threading.Lock()

    def expect(self, command_id: str) -> None:
        with self._lock:
            self.command_id, self.acked = command_id, set()
            self.done.clear()

    def on_accepted(self, topic: str, payload: bytes) -> None:
        if self.command_id.encode() not in payload:
            return  # cheap filter: 1,000 robots publish a lot
        reported = json.loads(payload)["state"].get("reported") or {}
        if (reported.get("last_command") or {}).get("id") != self.command_id:
            return
        parsed = topics.parse_shadow_topic(topic)
        with self._lock:
            if parsed is not None:
                if not self.acked:
                    self.first_at = time.perf_counter()
                self.acked.add(parsed[0])
            if len(self.acked) >= self.expected:
                self.last_at = time.perf_counter()
                self.done.set()


def swarm_process(broker: str, size: int, ready: Any, stop: Any) -> None:
    """The robots, in their own process as robots are on their own machines: the swarm
    must not share the shadow service's interpreter lock."""
    sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
    from tests.support.swarm import SwarmThread

    with SwarmThread(broker=broker, count=size, speed_factor=50):
        ready.set()
        stop.wait(600)


def run_size(stack: LocalStack, size: int, runs: int) -> list[float]:
    assert stack.mqtt_url is not None
    acks = Acknowledgments(size)
    data = boto3.client("iot-data", endpoint_url=stack.api_url, region_name="us-east-1")
    timings: list[float] = []
    with MqttClient(stack.service_endpoint()) as watcher:
        watcher.subscribe(topics.ALL_SHADOW_UPDATES_ACCEPTED, acks.on_accepted)
        context = multiprocessing.get_context("spawn")
        ready, stop = context.Event(), context.Event()
        robots = context.Process(target=swarm_process, args=(stack.mqtt_url, size, ready, stop))
        robots.start()
        try:
            if not ready.wait(60):
                raise RuntimeError(f"the swarm of {size} did not start")
            time.sleep(1.0 + size / 500)  # let start-up shadow reports settle
            for run in range(runs):
                command = new_command("ping" if run % 2 else "stop", source="console")
                acks.expect(command.id)
                started = time.perf_counter()
                data.publish(topic=topics.FLEET_CMD, qos=1, payload=encode(command))
                if not acks.done.wait(ACK_TIMEOUT_S):
                    raise RuntimeError(f"{size} robots: only {len(acks.acked)} acknowledged")
                timings.append((acks.last_at - started) * 1000)
                print(
                    f"{size}: first acknowledgment after {(acks.first_at - started) * 1000:.0f} ms",
                    file=sys.stderr,
                )
                time.sleep(0.5)
        finally:
            stop.set()
            robots.join(60)
            if robots.is_alive():
                robots.kill()
                robots.join(10)
    return timings


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--sizes", type=int, nargs="+", default=[10, 100, 1000])
    parser.add_argument("--runs", type=int, default=3)
    args = parser.parse_args()
    os.environ.setdefault("AWS_ACCESS_KEY_ID", "bench")
    os.environ.setdefault("AWS_SECRET_ACCESS_KEY", "bench")
    rows = []
    with tempfile.TemporaryDirectory(prefix="vahr-fanout-") as state:
        config = StackConfig(
            state_dir=Path(state), mqtts_port=free_port(), mqtt_port=free_port(),
            api_port=free_port(),
        )  # fmt: skip
        with LocalStack(config) as stack:
            for size in args.sizes:
                timings = run_size(stack, size, args.runs)
                rows.append((size, timings))
                print(f"{size} robots: {[round(t) for t in timings]} ms", file=sys.stderr)
    table = "\n".join(
        f"| {size} | {len(t)} | {median(t):.0f} | {min(t):.0f} | {max(t):.0f} | "
        f"{size / (median(t) / 1000):.0f} |"
        for size, t in rows
    )
    thousand = dict(rows).get(1000)
    verdict = (
        f"Target (1,000 robots in at most 2 s): {'met' if max(thousand) <= 2000 else 'NOT met'}"
        f" (worst run {max(thousand) / 1000:.2f} s)."
        if thousand
        else "The 1,000-robot size was not run."
    )
    body = f"""
One fleet command (an iot-data Publish to `vahr/fleet/cmd` through the local data plane)
until every robot's stored shadow reports that command as its `last_command` (swarm mode in its own
process: all agent cores on one event loop and one MQTT connection; the shadow service, the broker
and the swarm share the machine's 2 cores).

| robots | runs | median (ms) | best (ms) | worst (ms) | acknowledgments/s (median) |
| --- | --- | --- | --- | --- | --- |
{table}

{verdict}
"""
    write_section("fanout", "Fan-out of one fleet command", body)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
