"""Time `vahr up --swarm N` to ready, and weigh its swarm process.

For each size, starts `vahr up --swarm N --json` (station on, room voice off) on free
ports in a fresh state directory, and measures: seconds from the start to the endpoints
line (printed once every robot is online), the swarm process's resident memory then and
after 10 s idle, its CPU over those 10 s, and `vahr up`'s own resident memory. Then
stops it with SIGTERM. Writes its section into docs/benchmarks.md and prints one JSON line
per size. The largest size by default is `--swarm`'s bound (the most robots whose names
fit one Alexa interaction model).

    .venv/bin/python bench/swarm_startup.py [--sizes 100 1000 4000]
"""

from __future__ import annotations

import argparse
import json
import os
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from _results import write_section

from vahr.local.robots import SWARM_MAX
from vahr.plumbing.ports import free_port

IDLE_S = 10.0
TICKS = os.sysconf("SC_CLK_TCK")


def _swarm_pid(parent: int) -> int | None:
    for entry in Path("/proc").iterdir():
        if not entry.name.isdigit():
            continue
        try:
            command = (entry / "cmdline").read_bytes().split(b"\0")
            status = (entry / "status").read_text()
        except OSError:
            continue
        ppid = next(int(line.split()[1]) for line in status.splitlines() if line.startswith("PPid"))
        if ppid == parent and b"swarm" in command:
            return int(entry.name)
    return None


def _rss_mb(pid: int) -> float:
    status = Path(f"/proc/{pid}/status").read_text()
    kb = next(int(line.split()[1]) for line in status.splitlines() if line.startswith("VmRSS"))
    return kb / 1024


def _cpu_s(pid: int) -> float:
    fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / TICKS


def measure(size: int) -> dict[str, float | int | str]:
    with tempfile.TemporaryDirectory() as state:
        command = [
            sys.executable, "-m", "vahr.cli", "up", "--swarm", str(size), "--json",
            "--no-voice", "--state-dir", state, "--mqtt-port", "0",
            "--api-port", str(free_port()), "--mqtts-port", str(free_port()),
            "--station-port", str(free_port()),
        ]  # fmt: skip
        start = time.monotonic()
        up = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL)
        try:
            assert up.stdout is not None
            line = up.stdout.readline()
            ready_s = time.monotonic() - start
            if not line.startswith(b"{"):
                raise SystemExit(f"vahr up --swarm {size} did not start: {line!r}")
            swarm = _swarm_pid(up.pid)
            assert swarm is not None, "no swarm process found"
            rss_ready = _rss_mb(swarm)
            cpu_before = _cpu_s(swarm)
            time.sleep(IDLE_S)
            idle_cpu = (_cpu_s(swarm) - cpu_before) / IDLE_S
            figures: dict[str, float | int | str] = {
                "robots": size,
                "ready_s": round(ready_s, 2),
                "swarm_rss_ready_mb": round(rss_ready, 1),
                "swarm_rss_idle_mb": round(_rss_mb(swarm), 1),
                "swarm_idle_cpu_cores": round(idle_cpu, 3),
                "vahr_up_rss_mb": round(_rss_mb(up.pid), 1),
                "load": Path("/proc/loadavg").read_text().split()[0],
            }
        finally:
            up.send_signal(signal.SIGTERM)
            up.wait(120)
    return figures


# `vahr up --swarm 1000` is ready within this (the large-fleet target).
TARGET_1000_S = 30.0


def _row(r: dict[str, float | int | str]) -> str:
    ready = f"{r['ready_s']} s"
    if r["robots"] == 1000:
        verdict = "met" if float(r["ready_s"]) <= TARGET_1000_S else "NOT met"
        ready += f" (target {TARGET_1000_S:g} s: {verdict})"
    return (
        f"| {r['robots']:,} | {ready} | {r['swarm_rss_ready_mb']} MB | "
        f"{r['swarm_idle_cpu_cores']} core | {r['vahr_up_rss_mb']} MB | {r['load']} |"
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", type=int, nargs="+", default=[100, 1000, SWARM_MAX])
    args = parser.parse_args()
    results = [measure(size) for size in args.sizes]
    rows = "\n".join(_row(r) for r in results)
    for r in results:
        print(json.dumps(r))
    body = f"""
`vahr up --swarm N --json --no-voice` with the station, on free ports; ready is the start
to the endpoints line, printed once every robot is online. Resident memory and CPU are the
`robot-agent swarm` process's, CPU over 10 s idle after ready. One run per size.

| robots | ready | swarm RSS | swarm CPU idle | `vahr up` RSS | load |
| --- | --- | --- | --- | --- | --- |
{rows}

`--swarm` stops at {SWARM_MAX:,} robots: more robots' names make the interaction model larger than
Alexa's 1,000,000 characters (docs/large-fleets.md).
"""
    write_section("swarm_startup", "`vahr up --swarm N`: ready time and the swarm's weight", body)


if __name__ == "__main__":
    main()
