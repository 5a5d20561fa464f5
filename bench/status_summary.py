"""Time "where are the robots" against `vahr up --swarm N`: the whole turn and its words.

Starts `vahr up --swarm N --json --no-voice` on free ports, makes two robots stuck (`POST
/vahr/fault`, then a command to each), and asks `POST /vahr/say` the status question
`--turns` times, then "which robots are stuck?" as often. Prints the medians and p95 of
each turn's latency as the simulator measures it (utterance in, speech out: NLU, the
skill and its fleet-index calls), the words of the answers, the GetThingShadow calls the
meter counted during the questions, and one JSON line.

    .venv/bin/python bench/status_summary.py [--robots 1000] [--turns 30]
"""

from __future__ import annotations

import argparse
import json
import signal
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from vahr.plumbing.client import call
from vahr.plumbing.ports import free_port


def _p95(values: list[float]) -> float:
    ordered = sorted(values)
    return ordered[min(len(ordered) - 1, round(0.95 * (len(ordered) - 1)))]


def _turns(api: str, utterance: str, count: int) -> tuple[list[float], list[str]]:
    latencies, speeches = [], []
    for _ in range(count):
        turn = call(api, "POST", "/vahr/say", {"utterance": f"alexa ask robot fleet {utterance}"})
        latencies.append(float(turn["latency_ms"]))
        speeches.append(str(turn["speech"]))
    return latencies, speeches


def _wait_stuck(api: str, things: list[str], timeout_s: float = 60.0) -> None:
    deadline = time.monotonic() + timeout_s
    for thing in things:
        while call(api, "GET", f"/things/{thing}/shadow")["state"]["reported"]["status"] != "stuck":
            if time.monotonic() > deadline:
                raise SystemExit(f"{thing} did not get stuck")
            time.sleep(0.2)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--robots", type=int, default=1000)
    parser.add_argument("--turns", type=int, default=30)
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as state:
        command = [
            sys.executable, "-m", "vahr.cli", "up", "--swarm", str(args.robots), "--json",
            "--no-voice", "--state-dir", state, "--mqtt-port", "0", "--sim-speed-factor", "20",
            "--api-port", str(free_port()), "--mqtts-port", str(free_port()),
            "--station-port", str(free_port()),
        ]  # fmt: skip
        up = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL)
        try:
            assert up.stdout is not None
            api = json.loads(up.stdout.readline())["api"]
            stuck = ["rover17", f"rover{min(230, args.robots)}"]
            for thing, zone in zip(stuck, ("c", "a"), strict=True):
                call(api, "POST", "/vahr/fault", {"thing": thing, "fault": "stuck"})
                spoken = f"rover {thing.removeprefix('rover')}"
                call(api, "POST", "/vahr/say", {"utterance": f"alexa ask robot fleet to send "
                                                f"{spoken} to zone {zone}"})  # fmt: skip
            _wait_stuck(api, stuck)
            call(api, "POST", "/vahr/meter/reset", {})
            status_ms, status_said = _turns(api, "where are the robots", args.turns)
            stuck_ms, stuck_said = _turns(api, "which robots are stuck", args.turns)
            meter = call(api, "GET", "/vahr/meter")
        finally:
            up.send_signal(signal.SIGTERM)
            up.wait(120)
    reads = json.dumps(meter).count("http.shadow.get")
    load = Path("/proc/loadavg").read_text().split()[0]
    figures = {
        "robots": args.robots,
        "turns": args.turns,
        "status_p50_ms": round(statistics.median(status_ms), 1),
        "status_p95_ms": round(_p95(status_ms), 1),
        "status_words": max(len(s.split()) for s in status_said),
        "stuck_p50_ms": round(statistics.median(stuck_ms), 1),
        "stuck_p95_ms": round(_p95(stuck_ms), 1),
        "stuck_words": max(len(s.split()) for s in stuck_said),
        "shadow_reads_metered": reads,
        "load": load,
    }
    print(f"where are the robots: {status_said[-1]}")
    print(f"which robots are stuck: {stuck_said[-1]}")
    print(json.dumps(figures))


if __name__ == "__main__":
    main()
