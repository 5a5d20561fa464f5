"""A swarm whose robots all drive at once: what it sustains, and whether any robot says
"stuck" without being stuck.

For each size, a real mosquitto on a free loopback port and the product's swarm
(`robot_agent.swarm`) of that many robots in this process, with the settings `vahr up
--swarm` gives its robots (a progress report every wall-clock second). Every `LEG_S` wall seconds
one fleet-wide `navigate` sends every robot to zone A or D in turn (as bench/station.py
does), so every robot is always driving; nothing obstructs any of them, so every `stuck`
is a false one. Then, with `--arrive`, one last `navigate` to LOADING and the time until
every robot has arrived.

Measured over the window: shadow updates and events the robots published per second
(events split into progress and the rest), `stuck` and `failed` events, the event loop's
lag (how late a 50 ms timer fires: p50, p99, max), and the CPU the process used.

    .venv/bin/python bench/swarm_drive.py [--robots 1000 10000] [--seconds 60]
        [--speed-factor 5] [--arrive] [--write]
"""

from __future__ import annotations

import argparse
import asyncio
import json
import math
import sys
import tempfile
import time
from collections import Counter
from pathlib import Path
from typing import TYPE_CHECKING, Any

import msgspec
from _results import percentile, write_section

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from robot_agent.config import ExecutorSettings, SimSettings  # noqa: E402
from robot_agent.swarm import Swarm  # noqa: E402
from tests.support.swarm_runner import swarm_fleet  # noqa: E402
from vahr.local.robots import swarm_agent_config  # noqa: E402
from vahr.plumbing.ports import free_port  # noqa: E402
from vahr.protocol import encode, new_command, topics  # noqa: E402
from vahr.twin.broker import BrokerConfig, Mosquitto  # noqa: E402

if TYPE_CHECKING:
    from vahr.protocol import Event

LEG_S = 4.0  # wall seconds between fleet commands, as in bench/station.py
LAG_PROBE_S = 0.05


def swarm_settings(speed_factor: float) -> tuple[ExecutorSettings, SimSettings]:
    """The settings `vahr up --swarm` gives its robots (vahr.local.robots)."""
    config = msgspec.yaml.decode(swarm_agent_config(speed_factor))
    return (
        msgspec.convert(config.get("executor", {}), ExecutorSettings),
        msgspec.convert(config.get("sim", {}), SimSettings),
    )


class Tally:
    """Events by kind, as the robots publish them."""

    def __init__(self) -> None:
        self.kinds: Counter[str] = Counter()
        self.examples: list[str] = []

    def on_event(self, event: Event) -> None:
        self.kinds[event.event] += 1
        if event.event in ("stuck", "failed") and len(self.examples) < 3:
            self.examples.append(f"{event.thing} {event.event} {event.reason}")


async def _probe_lag(lags: list[float], stop: asyncio.Event) -> None:
    while not stop.is_set():
        before = time.perf_counter()
        await asyncio.sleep(LAG_PROBE_S)
        lags.append(time.perf_counter() - before - LAG_PROBE_S)


def _send(swarm: Swarm, zone: str) -> str:
    command = new_command("navigate", {"zone": zone}, source="console")
    assert swarm.link is not None
    swarm.link.publish(topics.FLEET_CMD, encode(command))
    return command.id


def _updates(swarm: Swarm) -> int:
    return sum(agent.shadow.updates_sent for agent in swarm.agents.values())


async def measure(size: int, args: argparse.Namespace, broker: str) -> dict[str, Any]:
    tally = Tally()
    fleet = swarm_fleet(size)
    started = time.monotonic()
    settings, sim = swarm_settings(args.speed_factor)
    swarm = Swarm(
        fleet=fleet,
        broker=broker,
        speed_factor=args.speed_factor,
        settings=settings,
        sim=sim,
        on_event=tally.on_event,
    )
    await swarm.start(timeout_s=60 + size / 100)
    ready_s = time.monotonic() - started
    lags: list[float] = []
    stop = asyncio.Event()
    prober = asyncio.create_task(_probe_lag(lags, stop))
    try:
        zones = ["A", "D"]
        _send(swarm, zones[0])
        await asyncio.sleep(LEG_S)  # warm-up leg, not counted
        tally.kinds.clear()
        lags.clear()
        updates_before, cpu_before = _updates(swarm), time.process_time()
        window_start = time.monotonic()
        leg = 1
        while time.monotonic() - window_start < args.seconds:
            _send(swarm, zones[leg % 2])
            leg += 1
            await asyncio.sleep(LEG_S)
        window = time.monotonic() - window_start
        updates = _updates(swarm) - updates_before
        cpu = time.process_time() - cpu_before
        kinds = dict(tally.kinds)
        window_lags = list(lags)
        figures: dict[str, Any] = {
            "robots": size,
            "speed_factor": args.speed_factor,
            "ready_s": round(ready_s, 1),
            # Commands the robots took (accepted) per second, against what was sent.
            "accepted_per_s": round(kinds.get("accepted", 0) / window),
            "sent_per_s": round(size / LEG_S),
            "updates_per_s": round(updates / window),
            "events_per_s": round(sum(kinds.values()) / window),
            "progress_per_s": round(kinds.get("progress", 0) / window),
            "stuck": kinds.get("stuck", 0),
            "failed": kinds.get("failed", 0),
            "lag_p50_ms": round(percentile(window_lags, 50) * 1000, 1),
            "lag_p99_ms": round(percentile(window_lags, 99) * 1000, 1),
            "lag_max_ms": round(max(window_lags) * 1000, 1),
            "cpu_cores": round(cpu / window, 2),
            "examples": tally.examples,
        }
        if args.arrive:
            figures.update(await _arrive(swarm, tally, args.speed_factor))
        figures["load"] = Path("/proc/loadavg").read_text().split()[0]
    finally:
        stop.set()
        await prober
        await swarm.stop(60)
    return figures


async def _arrive(swarm: Swarm, tally: Tally, speed_factor: float) -> dict[str, Any]:
    """Send everyone to LOADING and wait until all are done (or 3 times the ideal)."""
    loading = swarm.fleet.zone("LOADING").pose
    farthest = max(
        swarm.agents[thing].executor.backend.pose.distance_to(loading) for thing in swarm.things
    )
    # Straight line at the simulator's speed plus two turns of at most half a circle.
    ideal_s = (farthest / 0.5 + 2 * math.pi) / speed_factor
    tally.kinds.clear()
    started = time.monotonic()
    command_id = _send(swarm, "LOADING")
    deadline = started + 3 * ideal_s + 30
    arrived = 0
    while time.monotonic() < deadline:
        arrived = sum(
            1
            for thing in swarm.things
            if (last := swarm.state(thing).last_command) is not None
            and last.id == command_id
            and last.result == "done"
        )
        if arrived == len(swarm.things):
            break
        await asyncio.sleep(0.5)
    return {
        "arrived": arrived,
        "arrive_s": round(time.monotonic() - started, 1),
        "arrive_ideal_s": round(ideal_s, 1),
        "arrive_stuck": tally.kinds.get("stuck", 0),
    }


def run(size: int, args: argparse.Namespace) -> dict[str, Any]:
    with tempfile.TemporaryDirectory(prefix="vahr-swarm-drive-") as state:
        broker = Mosquitto(BrokerConfig(state_dir=Path(state), plain_port=free_port()))
        broker.start()
        try:
            return asyncio.run(measure(size, args, str(broker.plain_url)))
        finally:
            broker.stop()


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--robots", type=int, nargs="+", default=[1000, 10_000])
    parser.add_argument("--seconds", type=float, default=60.0)
    parser.add_argument("--speed-factor", type=float, default=5.0)
    parser.add_argument("--arrive", action="store_true", help="then time a drive to LOADING")
    parser.add_argument("--write", action="store_true", help="write docs/benchmarks.md")
    args = parser.parse_args()
    results = []
    for size in args.robots:
        figures = run(size, args)
        print(json.dumps(figures), flush=True)
        results.append(figures)
    if args.write:
        write_section("swarm_drive", "A swarm driving", _table(results, args))


def _table(results: list[dict[str, Any]], args: argparse.Namespace) -> str:
    rows = [
        "| robots | commands taken/s (sent) | shadow updates/s | events/s (progress) "
        "| false stuck | failed | loop lag p50 / p99 / max ms | CPU cores | load |",
        "| --- | --- | --- | --- | --- | --- | --- | --- | --- |",
    ]
    for r in results:
        rows.append(
            f"| {r['robots']:,} | {r['accepted_per_s']:,} ({r['sent_per_s']:,}) "
            f"| {r['updates_per_s']:,} | {r['events_per_s']:,} "
            f"({r['progress_per_s']:,}) | {r['stuck']} | {r['failed']} | {r['lag_p50_ms']} / "
            f"{r['lag_p99_ms']} / {r['lag_max_ms']} | {r['cpu_cores']} | {r['load']} |"
        )
    text = (
        f"Every robot driving for {args.seconds:g} s at {args.speed_factor:g} times real "
        f"time, a fleet `navigate` every {LEG_S:g} s, progress every wall-clock second "
        "(`vahr up --swarm`'s rate). Nothing obstructs any robot, so every `stuck` is false. "
        "CPU cores: what the one process got of the shared machine.\n\n" + "\n".join(rows)
    )
    arrivals = [r for r in results if "arrived" in r]
    if arrivals:
        text += (
            "\n\nThen one `navigate` to LOADING for all: "
            + "; ".join(
                f"{r['robots']:,} robots: {r['arrived']:,} arrived in {r['arrive_s']} s "
                f"(straight-line ideal {r['arrive_ideal_s']} s), {r['arrive_stuck']} stuck"
                for r in arrivals
            )
            + "."
        )
    return text


if __name__ == "__main__":
    main()
