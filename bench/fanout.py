"""Fan-out: one fleet command to 10 ... 10,000 robots until every shadow acknowledged.

The robots run in swarm mode (many agent cores on one event loop and one MQTT connection,
`tests.support.swarm_runner`) against the local stack. The command goes out as the skill sends it,
one iot-data Publish to `vahr/fleet/cmd` through the local data plane; the clock stops when
the shadow service has accepted, for every robot, a reported `last_command.id` equal to the
command's id (seen on `update/accepted`, which the shadow service publishes after storing).
Before each size is timed, the swarm's start-up reports (presence, a shadow update and a
get per robot) are left to settle until the shadow service has been quiet for a second.
Beside the time, each command's CPU: this process's (the local stack and the watcher) and the
swarm's. On 2 cores shared with other work the time follows the machine's load (written
beside the figures); the CPU says whether the code itself got slower.
Run: `.venv/bin/python bench/fanout.py [--sizes 10 100 1000 10000] [--runs 3]`.
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

from vahr.plumbing.mqtt import MqttClient  # noqa: E402
from vahr.plumbing.ports import free_port  # noqa: E402
from vahr.protocol import encode, new_command, topics  # noqa: E402
from vahr.twin.stack import LocalStack, StackConfig  # noqa: E402

ACK_TIMEOUT_S = 120.0
SETTLE_TIMEOUT_S = 120.0
TARGET_ROBOTS, TARGET_S = 10_000, 5.0
# Measured with this script before the shadow service batched its work (main at 123960d,
# 2026-11-22): robots -> median ms.
BEFORE_MS = {10: 21, 100: 150, 1000: 1233}
CLOCK_TICKS = os.sysconf("SC_CLK_TCK")
HEADER = (
    "| robots | runs | median (ms) | best (ms) | worst (ms) | acks/s (median) "
    "| CPU: stack / swarm (s) | before: median (ms) |\n"
    "| --- | --- | --- | --- | --- | --- | --- | --- |"
)


def own_cpu_s() -> float:
    usage = os.times()
    return usage.user + usage.system


def process_cpu_s(pid: int) -> float:
    fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / CLOCK_TICKS  # utime + stime


class Acknowledgments:
    """Which robots' stored shadows name the awaited command id."""

    def __init__(self, expected: int) -> None:
        self.expected = expected
        self.command_id = ""
        self.acked: set[str] = set()
        self.done = threading.Event()
        self.first_at = 0.0
        self.last_at = 0.0
        self.seen_at = time.monotonic()  # when any update/accepted last arrived
        self.seen = 0  # update/accepted messages of any command
        self._lock = threading.Lock()

    def expect(self, command_id: str) -> None:
        with self._lock:
            self.command_id, self.acked = command_id, set()
            self.done.clear()

    def on_accepted(self, topic: str, payload: bytes) -> None:
        self.seen_at = time.monotonic()
        self.seen += 1
        if not self.command_id or self.command_id.encode() not in payload:
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
    from tests.support.swarm_runner import SwarmThread

    with SwarmThread(broker=broker, count=size, speed_factor=50, listen_to_peers=False):
        ready.set()
        stop.wait(600)


def settle(acks: Acknowledgments, at_least: int = 0) -> None:
    """Wait until `at_least` more updates were accepted and then none for a second (the
    swarm's start-up reports, or the end of the previous run, are done)."""
    started, target = time.monotonic(), acks.seen + at_least
    deadline = started + SETTLE_TIMEOUT_S
    while acks.seen < target or time.monotonic() - acks.seen_at < 1.0:
        if time.monotonic() > deadline:
            raise RuntimeError(
                f"the shadow service did not settle ({acks.seen - target + at_least} of "
                f"{at_least} start-up reports)"
            )
        time.sleep(0.2)
    print(f"settled after {time.monotonic() - started:.1f} s", file=sys.stderr)


def run_size(stack: LocalStack, size: int, runs: int) -> list[tuple[float, float, float]]:
    """Each run's (milliseconds, this process's CPU s, the swarm's CPU s)."""
    assert stack.mqtt_url is not None
    acks = Acknowledgments(size)
    data = boto3.client("iot-data", endpoint_url=stack.api_url, region_name="us-east-1")
    timings: list[tuple[float, float, float]] = []
    with MqttClient(stack.service_endpoint()) as watcher:
        watcher.subscribe(topics.ALL_SHADOW_UPDATES_ACCEPTED, acks.on_accepted)
        context = multiprocessing.get_context("spawn")
        ready, stop = context.Event(), context.Event()
        robots = context.Process(target=swarm_process, args=(stack.mqtt_url, size, ready, stop))
        robots.start()
        try:
            if not ready.wait(180):
                raise RuntimeError(f"the swarm of {size} did not start")
            settle(acks, at_least=size)  # every robot reports its state once it is online
            for run in range(runs):
                command = new_command("stop" if run % 2 else "ping", source="console")
                acks.expect(command.id)
                assert robots.pid is not None
                own, swarm = own_cpu_s(), process_cpu_s(robots.pid)
                started = time.perf_counter()
                data.publish(topic=topics.FLEET_CMD, qos=1, payload=encode(command))
                if not acks.done.wait(ACK_TIMEOUT_S):
                    raise RuntimeError(f"{size} robots: only {len(acks.acked)} acknowledged")
                timings.append(
                    (
                        (acks.last_at - started) * 1000,
                        own_cpu_s() - own,
                        process_cpu_s(robots.pid) - swarm,
                    )
                )
                print(
                    f"{size}: first acknowledgment after {(acks.first_at - started) * 1000:.0f} ms",
                    file=sys.stderr,
                )
                settle(acks)
        finally:
            stop.set()
            robots.join(60)
            if robots.is_alive():
                robots.kill()
                robots.join(10)
    return timings


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--sizes", type=int, nargs="+", default=[10, 100, 1000, 10000])
    parser.add_argument("--runs", type=int, default=3)
    args = parser.parse_args()
    os.environ.setdefault("AWS_ACCESS_KEY_ID", "bench")
    os.environ.setdefault("AWS_SECRET_ACCESS_KEY", "bench")
    rows: list[tuple[int, list[tuple[float, float, float]]]] = []
    load_before = os.getloadavg()
    with tempfile.TemporaryDirectory(prefix="vahr-fanout-") as state:
        config = StackConfig(
            state_dir=Path(state), mqtts_port=free_port(), mqtt_port=free_port(),
            api_port=free_port(),
        )  # fmt: skip
        with LocalStack(config) as stack:
            for size in args.sizes:
                timings = run_size(stack, size, args.runs)
                rows.append((size, timings))
                print(f"{size} robots: {[round(t[0]) for t in timings]} ms", file=sys.stderr)
    load_after = os.getloadavg()
    lines = []
    for size, runs in rows:
        t = [run[0] for run in runs]
        own, swarm = median([run[1] for run in runs]), median([run[2] for run in runs])
        lines.append(
            f"| {size:,} | {len(t)} | {median(t):.0f} | {min(t):.0f} | {max(t):.0f} | "
            f"{size / (median(t) / 1000):,.0f} | {own:.2f} / {swarm:.2f} | "
            f"{BEFORE_MS.get(size, 'never tried')} |"
        )
    table = "\n".join(lines)
    target = {size: [run[0] for run in runs] for size, runs in rows}.get(TARGET_ROBOTS)
    verdict = (
        f"Target ({TARGET_ROBOTS:,} robots, median at most {TARGET_S:g} s): "
        f"{'met' if median(target) <= TARGET_S * 1000 else 'NOT met'}"
        f" (median {median(target) / 1000:.2f} s, worst run {max(target) / 1000:.2f} s)."
        if target
        else f"The {TARGET_ROBOTS:,}-robot size was not run."
    )
    body = f"""
One fleet command (an iot-data Publish to `vahr/fleet/cmd` through the local data plane)
until every robot's stored shadow reports that command as its `last_command` (swarm mode in its own
process: all agent cores on one event loop and one MQTT connection; the shadow service, the broker
and the swarm share the machine's 2 cores). Runs alternate `ping` (one shadow update per robot)
and `stop` (two: accepted, then stopped). CPU per command (median, seconds): this process's
(the local stack: broker client, shadow service, data plane; and the watcher's client) and the
swarm's; mosquitto's is not counted. Load average (1, 5, 15 min) before
{"/".join(f"{v:.2f}" for v in load_before)}, after {"/".join(f"{v:.2f}" for v in load_after)}.

{HEADER}
{table}

{verdict} Before: the shadow service applied, committed and answered each request on the MQTT
client's network thread, with a window of 20 messages in flight each way; 10,000 robots had
never been tried.
"""
    write_section("fanout", "Fan-out of one fleet command", body)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
