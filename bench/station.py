"""The operator station under load: a swarm of robots moving at once, in real Chromium.

`--robots N` robots, with the `--beside` fleet sizes (default 100) measured first in the same
run, each on a fresh stack, swarm, station and page, so the figures sit side by side.

- Shadow update to paint: the time from a robot's shadow update appearing on the broker
  (`update/documents`, as the station itself receives it) to the page having painted it
  (the page marks each shadow version it drew, after the frame; `?metrics=1`). p50 and p95
  over every update the page painted (a robot that changes again within a frame is painted
  once, at its latest version: the earlier version is not counted). Targets: p95 under
  100 ms with 1,000 robots, under 250 ms with 10,000.
- The page's memory (JS heap, from Chromium's performance metrics) after warming up and
  at the end of the run (10 minutes by default; `--minutes` for a shorter check).
- Push-to-talk round trip for a 2-second clip: from letting go of the button to the reply
  shown, beside the recognizer's own time for the clip.

Each part runs in its own process, as on a lab's machines: the local stack (broker, shadow
service, data plane, the Alexa simulator), the robots in swarm mode (`tests.support.swarm_runner`),
the station (`vahr station`, against the stack), the browser, and this script, which
notes when each shadow update reaches the broker. Every few seconds one fleet command sends
all robots to the other end of the floor.
Run: `.venv/bin/python bench/station.py [--minutes 10] [--robots 1000] [--beside 100 ...]
[--presses 5] [--no-voice]`. It prints its figures and ends with one JSON line: `{"robots":
N, "paint_p50_ms": ..., "paint_p95_ms": ..., ..., "beside": [{"robots": 100, ...}]}`.
`--no-voice` runs the station without push-to-talk, whose language model is built in a
child process (half a minute with 1,000 robots the first time, seconds from its cache;
docs/station.md), to see the intake without it; it writes nothing to docs/benchmarks.md.
"""

from __future__ import annotations

import argparse
import json
import math
import multiprocessing
import os
import signal
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path
from typing import Any

import msgspec
from _results import median, percentile, write_section

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from playwright.sync_api import TimeoutError as PlaywrightTimeout  # noqa: E402
from playwright.sync_api import sync_playwright  # noqa: E402

from tests.support.browser import launch  # noqa: E402
from tests.support.swarm_runner import swarm_fleet  # noqa: E402
from vahr.domain import load_fleet  # noqa: E402
from vahr.local.alexa_host import serve_alexa
from vahr.plumbing.lifetime import spawn  # noqa: E402
from vahr.plumbing.mqtt import MqttClient, MqttEndpoint  # noqa: E402
from vahr.plumbing.ports import free_port  # noqa: E402
from vahr.protocol import encode, new_command, topics  # noqa: E402
from vahr.protocol.broker import parse_broker_url  # noqa: E402
from vahr.speech.audio import Audio  # noqa: E402
from vahr.speech.tts import EspeakSynthesizer  # noqa: E402

SPEED_FACTOR = 5.0
LEG_S = 4.0  # wall seconds between fleet commands: robots are always on the move
CLIP = "what is the weather"
CLIP_S = 2.0


class BrokerClock:
    """When each (thing, shadow version) appeared on the broker."""

    def __init__(self) -> None:
        self.seen: dict[tuple[str, int], float] = {}
        self._lock = threading.Lock()

    def on_documents(self, topic: str, payload: bytes) -> None:
        at = time.time() * 1000
        parsed = topics.parse_shadow_topic(topic)
        if parsed is None or parsed[1] is not None:
            return
        version = json.loads(payload)["current"]["version"]
        with self._lock:
            self.seen[(parsed[0], int(version))] = at


def stack_process(state: str, ports: tuple[int, int, int], ready: Any, stop: Any) -> None:
    """The local stack with the Alexa simulator, in its own process."""
    sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
    from vahr.twin.stack import LocalStack, StackConfig

    mqtts, mqtt, api = ports
    config = StackConfig(state_dir=Path(state), mqtts_port=mqtts, mqtt_port=mqtt, api_port=api)
    with LocalStack(config) as stack:
        serve_alexa(stack)
        ready.set()
        stop.wait(7200)


def swarm_process(
    broker: str, size: int, ready: Any, stop: Any, base_file: str | None = None
) -> None:
    """The robots, in their own process as robots are on their own machines; with
    `base_file`, on that fleet's map."""
    sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
    from tests.support.swarm_runner import SwarmThread

    base = load_fleet(base_file) if base_file else None
    with SwarmThread(broker=broker, count=size, speed_factor=SPEED_FACTOR, base=base):
        ready.set()
        stop.wait(7200)


def feed_cost(robots: int, rounds: int = 5) -> dict[str, float]:
    """The station's own cost per robot update, apart from the machine's other work: a feed
    with one page takes `rounds` shadow documents and progress events of every robot (as
    the broker hands them over), and the page takes them once per round. Microseconds per
    document and per event, on one core; the best of three, as the least disturbed."""
    from vahr.protocol import Event, ReportedPose, utc_now
    from vahr.station.feed import Feed

    fleet = swarm_fleet(robots)
    documents, events = [], []
    for version in range(2, 2 + rounds):
        for index, thing in enumerate(fleet.robot_things):
            reported = {
                "status": "navigating", "zone": None, "cargo": False, "destination": "A",
                "pose": {"x": index + version * 0.1, "y": 2.0, "theta": 0.1}, "connected": True,
                "last_command": {"id": "c" * 32, "action": "navigate", "result": "accepted"},
            }  # fmt: skip
            state = {"state": {"reported": reported}, "metadata": {}}
            document = {
                "previous": {**state, "version": version - 1},
                "current": {**state, "version": version},
                "timestamp": version,
            }
            documents.append((topics.shadow(thing, "update/documents"), json.dumps(document)))
            event = Event(event="progress", thing=thing, at=utc_now(), progress=0.5,
                          pose=ReportedPose(1.0, 2.0))  # fmt: skip
            events.append((topics.robot_events(thing), encode(event)))
    best = {"document_us": float("inf"), "event_us": float("inf")}
    for _ in range(3):
        feed = Feed(fleet)
        page = feed.subscribe()
        page.take(0)
        started = time.perf_counter()
        for topic, payload in documents:
            feed.on_shadow_documents(topic, payload.encode())
        page.take(0)
        middle = time.perf_counter()
        for topic, event_payload in events:
            feed.on_event(topic, event_payload)
        page.take(0)
        ended = time.perf_counter()
        best["document_us"] = min(best["document_us"], (middle - started) / len(documents) * 1e6)
        best["event_us"] = min(best["event_us"], (ended - middle) / len(events) * 1e6)
    return {key: round(value, 1) for key, value in best.items()}


def heap_mb(cdp: Any) -> float:
    metrics = {m["name"]: m["value"] for m in cdp.send("Performance.getMetrics")["metrics"]}
    return float(metrics["JSHeapUsedSize"]) / 1e6


def collect(
    page: Any,
    clock: BrokerClock,
    latencies: list[float],
    arrivals: list[float] | None = None,
    at_station: list[float] | None = None,
) -> None:
    """Take the page's painted marks so far (and empty its list, so it does not grow)."""
    # The page's record of what it showed is for tests; emptied here so it does not grow.
    painted = page.evaluate(
        "() => { const m = window.vahrMetrics; m.shown.length = 0; return m.painted.splice(0); }"
    )
    for mark in painted:
        seen = clock.seen.get((mark["thing"], int(mark["version"])))
        if seen is not None:
            latencies.append(mark["at"] - seen)
            if arrivals is not None:
                arrivals.append(mark["received"] - seen)
            # When the station's feed took the document (its clock: the same machine's).
            if at_station is not None and mark.get("station"):
                at_station.append(mark["station"] - seen)


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--minutes", type=float, default=10.0)
    parser.add_argument("--robots", type=int, default=1000)
    parser.add_argument(
        "--beside", type=int, nargs="*", default=[100],
        help="smaller fleets measured first in the same run (default: 100)",
    )  # fmt: skip
    parser.add_argument("--presses", type=int, default=5)
    parser.add_argument(
        "--no-voice", action="store_true",
        help="a station without push-to-talk (no recognizer built in its process); prints its "
        "figures without writing docs/benchmarks.md",
    )  # fmt: skip
    parser.add_argument(
        "--map", action="store_true",
        help="the robots on a warehouse map the page draws under them (a floor that is a map)",
    )  # fmt: skip
    parser.add_argument(
        "--section", default="station",
        help="the section of docs/benchmarks.md to write (a long memory run keeps its own)",
    )  # fmt: skip
    args = parser.parse_args()
    if args.robots < 1 or any(size < 1 for size in args.beside):
        parser.error("--robots and --beside take whole numbers of at least 1")
    if args.no_voice:
        args.presses = 0
    runs = []
    for size in [*[s for s in args.beside if s != args.robots], args.robots]:
        load_before = os.getloadavg()
        run_args = argparse.Namespace(**{**vars(args), "robots": size})
        if size != args.robots:
            run_args.presses = 0
        latencies, result = measure(run_args)
        runs.append(figures(size, latencies, result, load_before))
        runs[-1]["feed"] = feed_cost(size)
        print(json.dumps(runs[-1]), flush=True)
    if not args.no_voice:
        report(args, runs)
    main_run = runs[-1]
    print(json.dumps({**main_run, "beside": runs[:-1]}))
    return 0


def measure(args: argparse.Namespace) -> tuple[list[float], dict[str, Any]]:
    """One fleet size: its own stack, swarm, station and page, for `args.minutes`."""
    clock = BrokerClock()
    latencies: list[float] = []
    context = multiprocessing.get_context("spawn")
    stop = context.Event()
    with tempfile.TemporaryDirectory(prefix="vahr-station-bench-") as folder:
        state = Path(folder)
        spoken = EspeakSynthesizer().synthesize(CLIP)
        pad = max(0.0, CLIP_S - spoken.seconds) / 2
        clip = Audio(Audio.silence(pad).pcm + spoken.pcm + Audio.silence(pad).pcm)
        microphone = state / "microphone.wav"
        microphone.write_bytes(clip.to_wav())
        fleet_file = state / "fleet.yaml"
        base_file = None
        if args.map:
            # A warehouse map sized for the fleet: the page draws it under the robots, and
            # the robots drive their planned paths on it.
            from tests.support.floor_maps import warehouse

            side = math.ceil(max(20.0, math.sqrt(args.robots) * 0.6 * 1.9 + 14.0) / 0.05)
            (state / "map").mkdir()
            base_file = str(warehouse(state / "map", side, side, robots=1))
        base = load_fleet(base_file) if base_file else None
        fleet_file.write_bytes(msgspec.yaml.encode(swarm_fleet(args.robots, base=base)))
        ports = (free_port(), free_port(), free_port())
        broker, api = f"mqtt://127.0.0.1:{ports[1]}", f"http://127.0.0.1:{ports[2]}"
        stack_ready, swarm_ready = context.Event(), context.Event()
        parts = [
            context.Process(
                target=stack_process, args=(str(state / "stack"), ports, stack_ready, stop)
            )
        ]
        parts[0].start()
        station: subprocess.Popen[str] | None = None
        try:
            if not stack_ready.wait(60):
                raise RuntimeError("the stack did not start")
            parts.append(
                context.Process(
                    target=swarm_process,
                    args=(broker, args.robots, swarm_ready, stop, base_file),
                )
            )
            parts[1].start()
            if not swarm_ready.wait(120 + args.robots / 50):
                raise RuntimeError("the swarm did not start")
            station, url = start_station(broker, api, fleet_file, voice=not args.no_voice)
            address = parse_broker_url(broker)
            with MqttClient(MqttEndpoint(host=address.host, port=address.port)) as link:
                link.subscribe(topics.ALL_SHADOW_DOCUMENTS, clock.on_documents)
                result = drive(args, url, link, microphone, clock, latencies, station.pid)
        finally:
            if station is not None and station.poll() is None:
                station.send_signal(signal.SIGTERM)
                station.wait(30)
            stop.set()
            for part in reversed(parts):
                part.join(60)
                if part.is_alive():
                    part.kill()
    return latencies, result


def start_station(
    broker: str, api: str, fleet_file: Path, *, voice: bool = True
) -> tuple[subprocess.Popen[str], str]:
    """`vahr station` against the stack, as a lab would run it; its page's URL."""
    voice_flags = [] if voice else ["--no-voice"]
    process = spawn(
        [sys.executable, "-m", "vahr.cli", "station", "--broker", broker, "--api", api,
         "--fleet", str(fleet_file), "--port", str(free_port()), "--json", *voice_flags],
        started_for=fleet_file.parent, stdout=subprocess.PIPE, text=True,
        cwd=Path(__file__).resolve().parents[1],
    )  # fmt: skip
    assert process.stdout is not None
    line = process.stdout.readline()
    if not line:
        raise RuntimeError("vahr station did not start")
    url: str = json.loads(line)["station"]
    return process, url


def drive(
    args: argparse.Namespace,
    url: str,
    link: MqttClient,
    microphone: Path,
    clock: BrokerClock,
    latencies: list[float],
    station_pid: int,
) -> dict[str, Any]:
    with sync_playwright() as playwright:
        browser = launch(playwright, microphone=microphone)
        page = browser.new_page(viewport={"width": 1280, "height": 800})
        page.context.grant_permissions(["microphone"])
        cdp = page.context.new_cdp_session(page)
        cdp.send("Performance.enable")
        page.goto(url + "?metrics=1")
        page.locator('#link-state[data-state="live"]').wait_for(timeout=30_000)
        zones = ["A", "D"]
        leg = 0
        arrivals: list[float] = []
        at_station: list[float] = []

        def send_everyone() -> None:
            nonlocal leg
            command = new_command("navigate", {"zone": zones[leg % 2]}, source="console")
            link.publish(topics.FLEET_CMD, encode(command))
            leg += 1

        # Warm up: one leg, then the first memory reading.
        send_everyone()
        time.sleep(LEG_S)
        collect(page, clock, [])
        heap_start = heap_mb(cdp)
        started, page_cpu, station_cpu = time.monotonic(), busy_s(cdp), cpu_s(station_pid)
        ends = time.monotonic() + args.minutes * 60
        while time.monotonic() < ends:
            send_everyone()
            time.sleep(LEG_S)
            collect(page, clock, latencies, arrivals, at_station)
        time.sleep(1.0)
        collect(page, clock, latencies, arrivals, at_station)
        elapsed = time.monotonic() - started
        page_share = (busy_s(cdp) - page_cpu) / elapsed
        station_share = (cpu_s(station_pid) - station_cpu) / elapsed
        cdp.send("HeapProfiler.collectGarbage")
        heap_end = heap_mb(cdp)
        messages = page.evaluate("() => window.vahrMetrics.messages")
        ptt = press(page, args.presses)
        browser.close()
    return {
        "heap_start": heap_start,
        "heap_end": heap_end,
        "messages": messages,
        "ptt": ptt,
        "arrivals": arrivals,
        "at_station": at_station,
        "page_busy": page_share,
        "station_cpu": station_share,
    }


def busy_s(cdp: Any) -> float:
    """Seconds the page's main thread has been busy (Chromium's TaskDuration)."""
    metrics = {m["name"]: m["value"] for m in cdp.send("Performance.getMetrics")["metrics"]}
    return float(metrics["TaskDuration"])


def cpu_s(pid: int) -> float:
    """CPU seconds (user and system) process `pid` and its threads have used."""
    fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def press(page: Any, presses: int) -> list[dict[str, Any]]:
    """Hold to talk for the clip's length, `presses` times; what the page measured."""
    box = page.locator("#talk").bounding_box()
    found: list[dict[str, Any]] = []
    for index in range(presses):
        page.mouse.move(box["x"] + box["width"] / 2, box["y"] + box["height"] / 2)
        page.mouse.down()
        time.sleep(CLIP_S + 0.2)
        page.mouse.up()
        try:
            page.wait_for_function(
                "(n) => window.vahrMetrics.ptt.length > n", arg=len(found), timeout=30_000
            )
        except PlaywrightTimeout:
            # Reported, not fatal: the paint figures of the run stand on their own.
            state = page.locator("#talk-state").inner_text()
            print(f"push-to-talk {index + 1}: no reply within 30 s ({state})", flush=True)
            continue
        found.append(page.evaluate("() => window.vahrMetrics.ptt.at(-1)"))
        time.sleep(0.5)
    return found


def figures(
    robots: int, latencies: list[float], result: dict[str, Any], load: tuple[float, ...]
) -> dict[str, Any]:
    """One fleet size's figures, as the JSON line has them."""
    if not latencies:
        raise RuntimeError(f"no shadow update was seen painted with {robots} robots")
    arrivals = result["arrivals"] or [0.0]
    ptt = result["ptt"]
    return {
        "robots": robots,
        "paint_p50_ms": round(percentile(latencies, 50), 1),
        "paint_p95_ms": round(percentile(latencies, 95), 1),
        "station_p50_ms": round(percentile(result["at_station"] or [0.0], 50), 1),
        "station_p95_ms": round(percentile(result["at_station"] or [0.0], 95), 1),
        "received_p50_ms": round(percentile(arrivals, 50), 1),
        "received_p95_ms": round(percentile(arrivals, 95), 1),
        "updates_painted": len(latencies),
        "page_messages": result["messages"],
        "page_main_thread_busy": round(result["page_busy"], 3),
        "station_cpu_cores": round(result["station_cpu"], 3),
        "heap_start_mb": round(result["heap_start"], 1),
        "heap_end_mb": round(result["heap_end"], 1),
        "ptt_reply_shown_ms": round(median([p["reply_shown_ms"] for p in ptt])) if ptt else None,
        "ptt_recognizer_ms": round(median([p["recognizer_ms"] for p in ptt])) if ptt else None,
        "heard": sorted({p["transcript"] for p in ptt}),
        "load_before": [round(value, 2) for value in load],
        "load_after": [round(value, 2) for value in os.getloadavg()],
    }


TARGETS = {1000: 100.0, 10000: 250.0}


def report(args: argparse.Namespace, measured: list[dict[str, Any]]) -> None:
    # The fleet sizes side by side, smallest first; push-to-talk is the main run's (the last).
    runs = sorted(measured, key=lambda run: run["robots"])

    def target(robots: int) -> str:
        limit = next((ms for size, ms in sorted(TARGETS.items()) if robots <= size), None)
        return f" (target under {limit:g} ms)" if limit else ""

    def row(name: str, key: str, unit: str = "ms") -> str:
        return f"| {name} | " + " | ".join(f"{run[key]} {unit}".strip() for run in runs) + " |"

    header = "| measure | " + " | ".join(f"{run['robots']:,} robots" for run in runs) + " |"
    verdicts = []
    for run in runs:
        limit = next((ms for size, ms in sorted(TARGETS.items()) if run["robots"] <= size), None)
        met = "" if limit is None else (" met" if run["paint_p95_ms"] < limit else " NOT met")
        verdicts.append(f"{run['paint_p95_ms']} ms{target(run['robots'])}{met}")
    rows = [
        header,
        "| --- |" + " --- |" * len(runs),
        row("shadow update on the broker to painted, p50", "paint_p50_ms"),
        "| shadow update on the broker to painted, p95 | " + " | ".join(verdicts) + " |",
        row("of which the broker to the station's feed taking it, p50", "station_p50_ms"),
        row("of which the broker to the station's feed taking it, p95", "station_p95_ms"),
        row("of which the broker to the page's receipt, p50", "received_p50_ms"),
        row("of which the broker to the page's receipt, p95", "received_p95_ms"),
        row("shadow updates painted", "updates_painted", ""),
        row("messages the page received", "page_messages", ""),
        row("the page's main thread busy (share of wall time)", "page_main_thread_busy", ""),
        row("`vahr station`'s CPU (cores used, on average)", "station_cpu_cores", ""),
        "| the station's feed alone, per shadow document / per progress event (one core) | "
        + " | ".join(f"{run['feed']['document_us']} / {run['feed']['event_us']} µs" for run in runs)
        + " |",
        row("page JS heap after warm-up", "heap_start_mb", "MB"),
        row(f"page JS heap after {args.minutes:g} minutes (after garbage collection)",
            "heap_end_mb", "MB"),
        "| load average (1, 5, 15 min) before / after | " + " | ".join(
            f"{'/'.join(map(str, run['load_before']))} / {'/'.join(map(str, run['load_after']))}"
            for run in runs) + " |",
    ]  # fmt: skip
    main_run = measured[-1]
    talk = ""
    if main_run["ptt_reply_shown_ms"] is not None:
        talk = (
            f"\nPush-to-talk with {main_run['robots']:,} robots moving, release to reply shown, "
            f'median of {args.presses} ({CLIP_S:g} s clip saying "{CLIP}", espeak-ng): '
            f"{main_run['ptt_reply_shown_ms']} ms, of which the recognizer "
            f"{main_run['ptt_recognizer_ms']} ms; heard: "
            f"{', '.join(repr(h) for h in main_run['heard'])}.\n"
        )
    body = f"""
Each fleet size on a fresh stack: robots in swarm mode (speed factor {SPEED_FACTOR:g}) sent
back and forth across the floor by one fleet command every {LEG_S:g} s for {args.minutes:g}
minutes, drawn by one station page (`vahr station`) in headless Chromium (1280x800). The
stack, the swarm, the station, the browser and this script are separate processes sharing
the machine's 2 cores with other work (the load average is beside the figures). A robot
that changes again within a frame is painted once, at its latest version; only painted
versions are counted.

{chr(10).join(rows)}
{talk}"""
    title = "Operator station: a fleet on the map, push-to-talk"
    if args.map:
        body = (
            "\nThe floor is a map (`--map`): a made-up warehouse sized for the fleet\n"
            "(tests/support/floor_maps.py), its occupancy image drawn under the robots, which\n"
            "drive their planned paths on it.\n" + body
        )
        title = f"Operator station on a map: {args.robots:,} robots, the map drawn"
    elif args.section != "station":
        title = f"Operator station: {args.robots:,} robots for {args.minutes:g} minutes"
    write_section(args.section, title, body, script="station")


if __name__ == "__main__":
    raise SystemExit(main())
