"""Planning on maps: one search from a goal, and a robot's path from it.

On the TurtleBot3 world (the SLAM map in docs/examples/turtlebot3_world, 384 x 384 cells of
5 cm) and on a made-up warehouse of `--cells` x `--cells` cells (default 4,000 x 4,000 at
5 cm: 200 m square, racks in rows; tests/support/floor_maps.py), both inflated by the
robot's radius:

- search: `Planner.field`, scikit-image's MCP_Geometric from a zone's cell over the whole
  map: every cell's path length to the zone. Done once per zone (and set of closed zones)
  by each process; every robot and every dispatch reads it after.
- plan: a robot's path from a random free place to a zone whose field is searched: the
  search's traceback and the line-of-sight shortening (`GoalField.route`), what a
  simulated robot does for each drive.
- plan, first: a new goal's search and one path together (the first drive to a zone).

Also the time to read the map and check the fleet on it (`load_floor`), and the process's
peak memory with the large map's fields.
"""

from __future__ import annotations

import argparse
import json
import random
import resource
import sys
import tempfile
import time
from pathlib import Path

from _results import median, percentile, write_section

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from tests.support.floor_maps import warehouse  # noqa: E402
from vahr.domain import load_fleet  # noqa: E402
from vahr.navigation import load_floor  # noqa: E402
from vahr.navigation.planner import GoalField  # noqa: E402

ROOT = Path(__file__).resolve().parent.parent
TURTLEBOT3 = ROOT / "docs/examples/turtlebot3_world/fleet.yaml"


def measure(
    fleet_file: Path, label: str, *, searches: int, plans: int, seed: int
) -> dict[str, object]:
    rng = random.Random(seed)
    fleet = load_fleet(fleet_file)
    began = time.perf_counter()
    floor = load_floor(fleet)
    load_s = time.perf_counter() - began
    assert floor is not None
    planner = floor.open
    zones = list(fleet.zones)
    search_ms = []
    fields = {}
    for number in range(searches):
        zone = zones[number % len(zones)]
        cell = planner.cell(zone.pose.x, zone.pose.y)
        began = time.perf_counter()
        field = GoalField(planner, cell, (zone.pose.x, zone.pose.y))
        search_ms.append((time.perf_counter() - began) * 1000)
        fields[zone.id] = field
    drivable = [tuple(int(v) for v in cell) for cell in _sample(planner.drivable, plans, rng)]
    plan_ms = []
    lengths = []
    for row, column in drivable:
        zone = rng.choice([z for z in zones if z.id in fields])
        x, y = floor.grid.centre(row, column)
        began = time.perf_counter()
        route = fields[zone.id].route(x, y, goal=(zone.pose.x, zone.pose.y))
        plan_ms.append((time.perf_counter() - began) * 1000)
        if route is not None:
            lengths.append(route.length)
    grid = floor.grid
    return {
        "map": label,
        "cells": f"{grid.columns} x {grid.rows}",
        "resolution_m": grid.resolution,
        "load_s": round(load_s, 2),
        "searches": len(search_ms),
        "search_p50_ms": round(median(search_ms), 1),
        "search_p95_ms": round(percentile(search_ms, 95), 1),
        "plans": len(plan_ms),
        "plan_p50_ms": round(median(plan_ms), 2),
        "plan_p95_ms": round(percentile(plan_ms, 95), 2),
        "first_plan_p50_ms": round(median(search_ms) + median(plan_ms), 1),
        "path_m_median": round(median(lengths), 1) if lengths else None,
        "peak_rss_mb": round(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024),
    }


def _sample(mask, count, rng):  # type: ignore[no-untyped-def]
    import numpy as np

    cells = np.argwhere(mask)
    return [cells[rng.randrange(len(cells))] for _ in range(count)]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cells", type=int, default=4000, help="the large map's side")
    parser.add_argument("--searches", type=int, default=25, help="on the real map")
    parser.add_argument("--large-searches", type=int, default=3)
    parser.add_argument("--plans", type=int, default=200)
    parser.add_argument("--seed", type=int, default=45)
    parser.add_argument("--no-write", action="store_true", help="print only")
    args = parser.parse_args()
    load = Path("/proc/loadavg").read_text().split()[:3]
    results = [
        measure(
            TURTLEBOT3,
            "TurtleBot3 world (SLAM)",
            searches=args.searches,
            plans=args.plans,
            seed=args.seed,
        )
    ]
    with tempfile.TemporaryDirectory(prefix="vahr-bench-floor-") as directory:
        large = warehouse(Path(directory), args.cells, args.cells, robots=1)
        results.append(
            measure(
                large,
                "made-up warehouse",
                searches=args.large_searches,
                plans=args.plans,
                seed=args.seed,
            )
        )
    for result in results:
        print(json.dumps(result))
    if args.no_write:
        return
    rows = "\n".join(
        f"| {r['map']} | {r['cells']} at {r['resolution_m']} m | {r['load_s']} "
        f"| {r['search_p50_ms']} / {r['search_p95_ms']} ({r['searches']}) "
        f"| {r['plan_p50_ms']} / {r['plan_p95_ms']} ({r['plans']}) | {r['first_plan_p50_ms']} "
        f"| {r['path_m_median']} | {r['peak_rss_mb']} |"
        for r in results
    )
    body = f"""
Load average while measuring: {" ".join(load)} (1, 5, 15 min; the machine is shared).
Search: one MCP_Geometric search from a zone over the whole inflated map (every cell's path
length to it), once per zone and set of closed zones in each process. Plan: one robot's
path from a random free place to a zone already searched (traceback and line-of-sight
shortening), what each drive costs. First plan: a zone's first drive (search and plan).

| map | cells | read and check s | search p50 / p95 ms (n) | plan p50 / p95 ms (n) \
| first plan p50 ms | path median m | peak RSS MB |
| --- | --- | ---: | ---: | ---: | ---: | ---: | ---: |
{rows}
"""
    write_section("floor_planning", "Floors on maps: searching and planning", body)


if __name__ == "__main__":
    main()
