"""Time the local fleet index's questions over 10,000 robots' shadows.

Fills an in-memory shadow store with N robots (99% idle, 0.8% navigating, 0.2% stuck,
over four zones), then times each question the dispatcher and the skill ask, in process,
and prints medians in milliseconds and one JSON line at the end.

    .venv/bin/python bench/fleet_index.py [--robots 10000] [--repeats 200]
"""

from __future__ import annotations

import argparse
import json
import statistics
import time
from pathlib import Path
from typing import TYPE_CHECKING

from vahr.twin.shadow_store import ShadowStore

if TYPE_CHECKING:
    from collections.abc import Callable


def fill(robots: int) -> ShadowStore:
    store = ShadowStore()
    statuses = ["idle"] * 990 + ["navigating"] * 8 + ["stuck"] * 2
    for number in range(robots):
        reported = {
            "status": statuses[number % len(statuses)],
            "zone": "ABCD"[number % 4],
            "connected": True,
            "pose": {"x": float(number % 100), "y": float(number // 100)},
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
        "idle_in_zone_C": lambda: index.search(
            "shadow.reported.status:idle AND shadow.reported.zone:C"
        ),
        "buckets_by_status": lambda: index.buckets("thingName:*", "shadow.reported.status"),
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


if __name__ == "__main__":
    main()
