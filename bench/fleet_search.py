"""What a submit and the schedule's search for robots low on charge cost the dispatcher
function in fleet-index calls among 10,000 robots.

Runs the dispatcher's own handler (`dispatcher.app.handle`) with its task table in moto's
DynamoDB, its commands through moto's iot-data and its candidates from a fleet index that
answers boto3's `iot` client with AWS's 100-thing pages (the local data plane's, over
HTTP on 127.0.0.1), and counts the SearchIndex calls of each submit. "Every page" is the
search as it was: every connected idle or busy robot, page after page (`FleetSearch`'s
`every_robot`, which orders for every idle robot still use); "idle first" is the search
a task uses now. Medians of `--repeats` submits (each cancelled after, so the fleet stays
free). Then the once-a-minute schedule's search for the idle robots under the fleet's
`charge_below`, 1 robot in 100 low: every page of idle robots, filtered here, as it read
before, against `FleetSearch.low_idle`, a range on the indexed charge. Its section is
written into docs/benchmarks.md, and one JSON line at the end.

    .venv/bin/python bench/fleet_search.py [--robots 10000] [--repeats 5]
"""

from __future__ import annotations

import argparse
import contextlib
import json
import os
import statistics
import sys
import time
from collections import Counter
from datetime import UTC, datetime
from pathlib import Path
from typing import TYPE_CHECKING, Any

from _results import write_section

ROOT = Path(__file__).resolve().parents[1]
# The dispatcher function's code root (`lambda/`), as pytest's `pythonpath` has it.
sys.path[:0] = [str(ROOT / "lambda"), str(ROOT)]

import boto3  # noqa: E402
from moto import mock_aws  # noqa: E402

from dispatcher import app  # noqa: E402
from dispatcher.command_channel import CommandChannel  # noqa: E402
from dispatcher.fleet_search import PAGE_SIZE, FleetSearch, status_query  # noqa: E402
from dispatcher.task_table import TaskTable  # noqa: E402
from tests.support.dispatch_meter import REGION, TABLE  # noqa: E402
from tests.support.dynamodb_tables import create_task_table  # noqa: E402
from vahr.dispatch import IDLE_STATUSES, Dispatcher  # noqa: E402
from vahr.domain import load_fleet  # noqa: E402
from vahr.twin.dataplane import DataPlane, DataPlaneServer  # noqa: E402
from vahr.twin.meter import Meter  # noqa: E402
from vahr.twin.shadow_service import ShadowService  # noqa: E402
from vahr.twin.shadow_store import ShadowStore  # noqa: E402

if TYPE_CHECKING:
    from collections.abc import Callable

# The fleets: every robot idle; every robot busy on work given by name (the idle search
# finds none); a fleet mostly busy, with 1 robot in 100 idle.
FLEETS: dict[str, Callable[[int], str]] = {
    "all idle": lambda n: "idle",
    "all busy": lambda n: "navigating",
    "1 % idle": lambda n: "idle" if n % 100 == 0 else "navigating",
}


# The schedule's threshold: the fleet file's default `charge_below`.
CHARGE_BELOW = 20
HEAD = (
    "| fleet | SearchIndex calls, every page | ms, every page | SearchIndex calls, idle first "
    "| ms, idle first | faster |\n| --- | ---: | ---: | ---: | ---: | ---: |"
)


def fill(
    robots: int, status_of: Callable[[int], str], percent_of: Callable[[int], int] | None = None
) -> ShadowStore:
    store = ShadowStore(None)
    for n in range(robots):
        reported = {
            "status": status_of(n),
            "zone": "ABCD"[n % 4],
            "connected": True,
            "pose": {"x": float(n % 100) / 10, "y": float(n // 100) / 10},
            "battery": {"percent": (percent_of or _charged)(n), "charging": False},
        }
        store.update(f"rover{n:05}", None, json.dumps({"state": {"reported": reported}}).encode())
    return store


def _charged(n: int) -> int:
    return 20 + n % 80


def _one_in_a_hundred_low(n: int) -> int:
    return 7 if n % 100 == 50 else 20 + n % 80


def low_searches(store: ShadowStore, repeats: int) -> dict[str, tuple[float, float, int]]:
    """For each way of finding the idle robots under `CHARGE_BELOW`: the median of
    SearchIndex calls, of milliseconds, and how many robots it found."""
    server = DataPlaneServer(DataPlane(ShadowService(store, publish=lambda *_: None),
                                       publish=lambda *_: None, meter=Meter()), 0)  # fmt: skip
    with server:
        iot = boto3.client("iot", endpoint_url=server.url)
        counted: Counter[str] = Counter()
        iot.meta.events.register("before-call.iot.SearchIndex", lambda **_: counted.update(["x"]))

        def every_idle_page() -> int:
            # The schedule's search before: every page of connected idle robots, the low
            # ones picked out of them afterwards.
            low = 0
            request = {"indexName": "AWS_Things", "maxResults": PAGE_SIZE,
                       "queryString": status_query(IDLE_STATUSES)}  # fmt: skip
            while True:
                page = iot.search_index(**request)
                for thing in page["things"]:
                    battery = json.loads(thing["shadow"])["reported"]["battery"]
                    low += battery["percent"] < CHARGE_BELOW
                if not page.get("nextToken"):
                    return low
                request["nextToken"] = page["nextToken"]

        def by_range() -> int:
            return len(FleetSearch(client=iot).low_idle(CHARGE_BELOW))

        results = {}
        for name, search in (("every idle page", every_idle_page), ("range", by_range)):
            calls, times, found = [], [], 0
            for _ in range(repeats):
                counted.clear()
                start = time.perf_counter()
                found = search()
                times.append((time.perf_counter() - start) * 1000)
                calls.append(counted["x"])
            results[name] = (statistics.median(calls), statistics.median(times), found)
    return results


def submits(store: ShadowStore, *, every_page: bool, repeats: int) -> tuple[list[int], list[float]]:
    """SearchIndex calls and milliseconds of `repeats` submits of a delivery to zone C."""
    server = DataPlaneServer(DataPlane(ShadowService(store, publish=lambda *_: None),
                                       publish=lambda *_: None, meter=Meter()), 0)  # fmt: skip
    calls: list[int] = []
    times: list[float] = []
    with mock_aws(), server:
        dynamodb = boto3.client("dynamodb", region_name=REGION)
        create_task_table(dynamodb, TABLE)
        table = TaskTable(TABLE, client=dynamodb)
        iot = boto3.client("iot", endpoint_url=server.url)
        counted: Counter[str] = Counter()
        iot.meta.events.register("before-call.iot.SearchIndex", lambda **_: counted.update(["x"]))
        search = FleetSearch(client=iot, holding=table.holders)
        dispatcher = Dispatcher(
            fleet=load_fleet(),
            store=table,
            candidates=search,
            publish=CommandChannel(client=boto3.client("iot-data", region_name=REGION)),
            clock=lambda: datetime.now(UTC),
        )
        for _ in range(repeats):
            counted.clear()
            order = {"operation": "submit", "order": {"kind": "deliver", "zone": "C"}}
            start = time.perf_counter()
            with search.every_robot() if every_page else contextlib.nullcontext():
                answer: dict[str, Any] = app.handle(order, dispatcher)
            times.append((time.perf_counter() - start) * 1000)
            calls.append(counted["x"])
            [task] = answer["body"]["assigned"]
            app.handle({"operation": "cancel", "task_id": task["id"]}, dispatcher)
    return calls, times


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--robots", type=int, default=10_000)
    parser.add_argument("--repeats", type=int, default=5)
    args = parser.parse_args()
    for name in ("AWS_ACCESS_KEY_ID", "AWS_SECRET_ACCESS_KEY"):
        os.environ.setdefault(name, "bench")
    os.environ["AWS_DEFAULT_REGION"] = REGION
    rows, figures = [], {}
    for fleet, status_of in FLEETS.items():
        store = fill(args.robots, status_of)
        before_calls, before_ms = submits(store, every_page=True, repeats=args.repeats)
        after_calls, after_ms = submits(store, every_page=False, repeats=args.repeats)
        before, after = statistics.median(before_ms), statistics.median(after_ms)
        rows.append(
            f"| {fleet} | {statistics.median(before_calls):g} | {before:,.0f} | "
            f"{statistics.median(after_calls):g} | {after:,.0f} | {before / after:,.1f}x |"
        )
        key = fleet.replace(" % ", "pct_").replace(" ", "_")
        figures[key] = {"calls_before": statistics.median(before_calls),
                        "ms_before": round(before), "calls_after": statistics.median(after_calls),
                        "ms_after": round(after)}  # fmt: skip
        print(rows[-1], flush=True)
    low = low_searches(fill(args.robots, FLEETS["all idle"], _one_in_a_hundred_low), args.repeats)
    scan, ranged = low["every idle page"], low["range"]
    assert scan[2] == ranged[2], f"the range found {ranged[2]} robots, every page {scan[2]}"
    figures["low_on_charge"] = {
        "calls_before": scan[0], "ms_before": round(scan[1]),
        "calls_after": ranged[0], "ms_after": round(ranged[1]), "found": ranged[2],
    }  # fmt: skip
    print(figures["low_on_charge"], flush=True)
    low_rows = (
        f"| every page of idle robots, the low ones picked out (before) | {scan[0]:g} | "
        f"{scan[1]:,.0f} | {scan[2]} |\n"
        f"| a range on the indexed charge, `shadow.reported.battery.percent<{CHARGE_BELOW}` "
        f"(now) | {ranged[0]:g} | {ranged[1]:,.0f} | {ranged[2]} |"
    )
    load = Path("/proc/loadavg").read_text().split()[0]
    body = f"""
SearchIndex calls and wall time of one submit ("deliver a package to zone C") through the
dispatcher function's handler among {args.robots:,} connected robots, the task table in
moto's DynamoDB and the fleet index answering boto3's `iot` client over HTTP on 127.0.0.1
with AWS's 100-thing pages; medians of {args.repeats} submits. "Every page": every idle or
busy robot, page after page, as a submit searched before (still the search of orders for
every idle robot, a group's members or the robots in a zone); "idle first": the connected
idle robots first, reading on only while no robot found is free, then the busy ones.
Load average {load} when it ran.

{HEAD}
{chr(10).join(rows)}

A busy robot is sent only when no idle one is free, so with none idle the idle search finds
nothing (one call) and the first page of busy robots answers (one more). The times are the
local index's; on AWS each SearchIndex call is a round trip to the IoT control plane, one
after the other, so the calls saved are the time saved. In the index's bill a submit is one
query whatever the fleet's size (the section "Billable AWS operations per dispatched task
and per status question, by fleet size").

The once-a-minute schedule, when the fleet's batteries drain, looks for the idle robots
under `charge_below` ({CHARGE_BELOW} percent) to send them to charge. Among the same
{args.robots:,} robots, all idle, 1 in 100 of them low ({ranged[2]} robots), medians of
{args.repeats} searches:

| search | SearchIndex calls | ms | robots found |
| --- | ---: | ---: | ---: |
{low_rows}
"""
    print(json.dumps({"robots": args.robots, **figures, "load": load}))
    title = f"Fleet dispatch on AWS: a submit among {args.robots:,} robots"
    write_section("fleet_search", title, body)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
