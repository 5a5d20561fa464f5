"""Time the local fleet index's questions over 10,000 robots' shadows.

Fills an in-memory shadow store with N robots (99% idle, 0.8% navigating, 0.2% stuck,
over four zones, charged 1 to 100 percent), then times each question the dispatcher and
the skill ask, in process; medians in milliseconds, written into docs/benchmarks.md, and
one JSON line at the end.

    .venv/bin/python bench/fleet_index.py [--robots 10000] [--repeats 200]
"""

from __future__ import annotations

import argparse
import json
import statistics
import time
from pathlib import Path
from typing import TYPE_CHECKING

from _results import write_section

from vahr.twin.shadow_store import ShadowStore

if TYPE_CHECKING:
    from collections.abc import Callable

IDLE_IN_ZONE_C = "shadow.reported.status:idle AND shadow.reported.zone:C"
IDLE_UNDER_20 = "shadow.reported.status:idle AND shadow.reported.battery.percent<20"


def fill(robots: int) -> ShadowStore:
    store = ShadowStore()
    statuses = ["idle"] * 990 + ["navigating"] * 8 + ["stuck"] * 2
    for number in range(robots):
        reported = {
            "status": statuses[number % len(statuses)],
            "zone": "ABCD"[number % 4],
            "connected": True,
            "pose": {"x": float(number % 100), "y": float(number // 100)},
            "battery": {"percent": 1 + number % 100, "charging": False},
        }
        body = json.dumps({"state": {"reported": reported}}).encode()
        store.update(f"rover{number}", None, body, commit=False)
    return store


def median_ms(question: Callable[[], object], repeats: int) -> float:
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        question()
        times.append((time.perf_counter() - start) * 1000)
    return statistics.median(times)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--robots", type=int, default=10_000)
    parser.add_argument("--repeats", type=int, default=200)
    args = parser.parse_args()
    start = time.perf_counter()
    store = fill(args.robots)
    fill_s = time.perf_counter() - start
    index = store.index
    questions: dict[str, Callable[[], object]] = {
        "status_counts": index.status_counts,
        "stuck_robots": lambda: index.with_status("stuck"),
        "idle_in_zone_C": lambda: index.search(IDLE_IN_ZONE_C),
        "buckets_by_status": lambda: index.buckets("thingName:*", "shadow.reported.status"),
        "idle_under_20_percent": lambda: index.search(IDLE_UNDER_20),
        "update_one_robot": lambda: store.update(
            "rover17", None, b'{"state":{"reported":{"status":"navigating"}}}', commit=False
        ),
    }
    figures: dict[str, float] = {}
    for name, question in questions.items():
        figures[f"{name}_p50_ms"] = round(median_ms(question, args.repeats), 3)
        print(f"{name:>20}: {figures[f'{name}_p50_ms']:.3f} ms (median of {args.repeats})")
    load = Path("/proc/loadavg").read_text().split()[0]
    print(f"{args.robots} robots indexed in {fill_s:.2f} s; load average {load}")
    print(json.dumps({"robots": args.robots, "fill_s": round(fill_s, 2), **figures, "load": load}))
    found = {
        "stuck": len(index.with_status("stuck")),
        "in_zone": len(index.search(IDLE_IN_ZONE_C)),
        "low": len(index.search(IDLE_UNDER_20)),
    }
    rows = [
        ("counts by status", figures["status_counts_p50_ms"]),
        (f"the stuck robots ({found['stuck']:,})", figures["stuck_robots_p50_ms"]),
        (f"the idle robots in zone C ({found['in_zone']:,}), by query string",
         figures["idle_in_zone_C_p50_ms"]),
        ("buckets by status over `thingName:*`", figures["buckets_by_status_p50_ms"]),
        (f"the idle robots under 20 percent ({found['low']:,}), by a range "
         "on the charge", figures["idle_under_20_percent_p50_ms"]),
        ("one shadow update, index included", figures["update_one_robot_p50_ms"]),
    ]  # fmt: skip
    table = "\n".join(f"| {what} | {ms:.3f} ms |" for what, ms in rows)
    body = f"""
{args.robots:,} robots' shadows in an in-memory shadow store (99% idle, 0.8% navigating,
0.2% stuck, over four zones, charged 1 to 100 percent); medians of {args.repeats} calls,
in process. Load average {load} when it ran.

| question | median |
| --- | --- |
{table}
| {args.robots:,} shadows stored and indexed | {fill_s:.2f} s |

The charge has no secondary index: a range over it reads every robot once, which the
dispatcher asks once a minute and the skill when someone asks which robots are low.
"""
    write_section("fleet_index", f"Local fleet index: questions over {args.robots:,} robots", body)


if __name__ == "__main__":
    main()
