"""Write one benchmark's results into its own section of docs/benchmarks.md.

Each benchmark owns the text between `<!-- bench:NAME -->` and `<!-- /bench:NAME -->`, so
scripts can run in any order and rerunning one replaces only its own numbers. The page is
organised by area (`AREAS`), not by the date a figure arrived: a new section goes at the
end of its area, and a section no area names is refused (name it in `AREAS` first).
"""

from __future__ import annotations

import os
import platform
import statistics
from datetime import UTC, datetime
from pathlib import Path

RESULTS_FILE = Path(__file__).resolve().parents[1] / "docs" / "benchmarks.md"
HEADER = (
    "# Benchmarks\n\n"
    "Measured by the scripts in `bench/` (`make bench` runs them all), organised by area.\n"
    "Each section is rewritten by its own script; every comparison in a section comes from\n"
    "one run.\n"
)


# The page's areas in order: (marker, heading, the sections in it, in order).
AREAS: tuple[tuple[str, str, tuple[str, ...]], ...] = (
    ("understanding", "Understanding people", (
        "understanding", "nlu_devset", "nlu_roles_devset", "roles_calibration",
        "understanding_locales", "nlu_devset_de",
    )),
    ("hearing", "Hearing people", (
        "hearing", "hearing_voices", "voice_roundtrip", "station_hearing",
        "station_hearing_reply", "station_answers", "wrong_actions", "wrong_stops",
    )),
    ("station", "The operator station", (
        "station", "station_map", "station-memory", "announcement", "say_latency",
        "mqtt_intake",
    )),
    ("fleet", "The fleet", (
        "fanout", "shadow_throughput", "fleet_index", "dispatch", "floor_planning",
        "status_summary", "swarm_startup", "swarm_drive", "shift",
    )),
    ("robots", "Robots and the wire", (
        "protocol_import", "agent_footprint", "nav2_goal_latency",
    )),
    ("aws", "AWS: cold starts and cost", (
        "skill_cold_start", "lambda_bundle", "billable_operations",
        "billable_operations_fleet", "fleet_search", "audit_trail",
    )),
    ("reliability", "Reliability", ("dataplane_load", "fuzz", "soak")),
    ("experiment", "The experiment", ("experiment_log", "rehearsal")),
)  # fmt: skip


def area_of(name: str) -> str:
    """The marker of the area a section belongs to; ValueError for a section in none."""
    for marker, _, names in AREAS:
        if name in names:
            return marker
    raise ValueError(f"section {name!r} is in no area of bench/_results.py's AREAS")


def percentile(values: list[float], pct: float) -> float:
    """The `pct` percentile (0-100) with linear interpolation."""
    ordered = sorted(values)
    if not ordered:
        raise ValueError("no values")
    rank = (len(ordered) - 1) * pct / 100
    low = int(rank)
    high = min(low + 1, len(ordered) - 1)
    return ordered[low] + (ordered[high] - ordered[low]) * (rank - low)


def median(values: list[float]) -> float:
    return statistics.median(values)


def machine() -> str:
    python = f"{platform.python_implementation()} {platform.python_version()}"
    return f"{python}, {os.cpu_count()} cores, {platform.machine()}"


def write_section(name: str, title: str, body: str, *, script: str | None = None) -> None:
    """Replace (or add, at the end of its area) the section `name` in docs/benchmarks.md
    and print it; `script` names the script when it is not `bench/{name}.py` (one script
    writing two sections)."""
    area = area_of(name)
    stamp = datetime.now(UTC).strftime("%Y-%m-%d %H:%M UTC")
    section = (
        f"<!-- bench:{name} -->\n### {title}\n\n"
        f"`bench/{script or name}.py`, {stamp}, {machine()}.\n\n{body.strip()}\n"
        f"<!-- /bench:{name} -->"
    )
    text = RESULTS_FILE.read_text() if RESULTS_FILE.exists() else _empty_page()
    start, end = f"<!-- bench:{name} -->", f"<!-- /bench:{name} -->"
    if start in text and end in text:
        before, rest = text.split(start, 1)
        after = rest.split(end, 1)[1]
        text = before + section + after
    else:
        closing = f"<!-- /area:{area} -->"
        if closing not in text:
            raise ValueError(f"docs/benchmarks.md has no area {area!r}; write its markers")
        before, after = text.split(closing, 1)
        text = before.rstrip("\n") + "\n\n" + section + "\n\n" + closing + after
    RESULTS_FILE.parent.mkdir(parents=True, exist_ok=True)
    RESULTS_FILE.write_text(text)
    print(section)


def _empty_page() -> str:
    areas = "".join(
        f"\n<!-- area:{marker} -->\n## {heading}\n\n<!-- /area:{marker} -->\n"
        for marker, heading, _ in AREAS
    )
    return HEADER + areas
