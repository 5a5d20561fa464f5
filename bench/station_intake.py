"""The station's MQTT intake alone: a fleet command's burst, from the broker to the feed.

A real mosquitto on loopback; a publisher process sends what the station receives after one
fleet command to `--robots` robots, robot by robot: a shadow `update/documents`, an
`accepted` event and `--progress` progress events each (the swarm's shape), as fast as its
client goes. The station's own client and `Feed` (as `vahr station` wires them, one page
subscribed and drained every frame) take them. Figures: the time from each document being
published to the feed having taken it (p50, p95, max), the time until the last message of
the burst was taken, and the station's CPU per message. With `--held` the station's network
thread is held at the burst's first message until the whole burst waits at the broker, so
the time to take it is the station's alone (the publisher is not the pace): microseconds
per message, the intake's throughput. `--bursts` bursts, one every
`--gap` seconds; medians over bursts. No browser: `bench/station.py` measures the whole
path; this isolates the part that was slow.

Run: `.venv/bin/python bench/station_intake.py [--robots 1000] [--bursts 5]`; prints one
JSON line.
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

from _results import median, percentile

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from tests.support.swarm_runner import swarm_fleet  # noqa: E402
from vahr.plumbing.mqtt import MqttClient, MqttEndpoint  # noqa: E402
from vahr.plumbing.ports import free_port  # noqa: E402
from vahr.protocol import Event, ReportedPose, encode, topics, utc_now  # noqa: E402
from vahr.station.assembly import Station, StationConfig  # noqa: E402
from vahr.station.feed import Feed  # noqa: E402
from vahr.twin.broker import BrokerConfig, Mosquitto  # noqa: E402


def burst_payloads(things: list[str], version: int, progress: int) -> list[tuple[str, bytes]]:
    """One fleet command's answers, robot by robot, as the station receives them."""
    found: list[tuple[str, bytes]] = []
    for index, thing in enumerate(things):
        reported = {
            "status": "navigating", "zone": None, "cargo": False, "destination": "A",
            "pose": {"x": index * 0.5, "y": 2.0, "theta": 0.1}, "connected": True,
            "last_command": {"id": f"c{version:031d}", "action": "navigate",
                             "result": "accepted"},
        }  # fmt: skip
        state = {"state": {"reported": reported}, "metadata": {}}
        document = {
            "previous": {**state, "version": version - 1},
            "current": {**state, "version": version},
            "timestamp": version,
        }
        accepted = Event(event="accepted", thing=thing, at=utc_now())
        found.append((topics.robot_events(thing), encode(accepted)))
        found.append((topics.shadow(thing, "update/documents"), json.dumps(document).encode()))
        for step in range(progress):
            share = (step + 1) / (progress + 1)
            event = Event(
                event="progress", thing=thing, at=utc_now(), progress=share, pose=ReportedPose(1, 2)
            )
            found.append((topics.robot_events(thing), encode(event)))
    return found


def publisher(port: int, things: list[str], args: Any, ready: Any, sent: Any) -> None:
    """Publish `args.bursts` bursts; put each document's send time (ms) on `sent`."""
    with MqttClient(MqttEndpoint(host="127.0.0.1", port=port)) as link:
        ready.wait(60)
        for burst in range(args.bursts):
            payloads = burst_payloads(things, burst + 2, args.progress)
            times: dict[str, float] = {}
            for topic, payload in payloads:
                if topic.endswith("update/documents"):
                    times[topic] = time.time() * 1000
                link.publish(topic, payload, qos=1, wait=False)
            sent.put(times)
            time.sleep(args.gap)


def cpu_s() -> float:
    usage = os.times()
    return usage.user + usage.system


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--robots", type=int, default=1000)
    parser.add_argument("--progress", type=int, default=2, help="progress events per robot")
    parser.add_argument("--bursts", type=int, default=5)
    parser.add_argument("--gap", type=float, default=3.0, help="seconds between bursts")
    parser.add_argument("--held", action="store_true", help="time the station's intake alone")
    args = parser.parse_args()
    fleet = swarm_fleet(args.robots)
    things = list(fleet.robot_things)
    per_burst = len(burst_payloads(things[:1], 2, args.progress)) * len(things)
    context = multiprocessing.get_context("spawn")
    with tempfile.TemporaryDirectory(prefix="vahr-intake-") as folder:
        port = free_port()
        with Mosquitto(BrokerConfig(state_dir=Path(folder), plain_port=port)):
            taken: dict[str, float] = {}
            counted = [0]
            done, released = threading.Event(), threading.Event()
            release_at = [0.0]
            feed = Feed(fleet)
            link = MqttClient(MqttEndpoint(host="127.0.0.1", port=port)).connect()

            def timed(handler: Any) -> Any:
                def handle(topic: str, payload: bytes) -> None:
                    if args.held and counted[0] % per_burst == 0:
                        released.wait(120)  # the burst queues up behind this message
                        released.clear()
                    handler(topic, payload)
                    if topic.endswith("update/documents"):
                        taken[topic] = time.time() * 1000
                    counted[0] += 1
                    if counted[0] % per_burst == 0:
                        done.set()

                return handle

            feed.routes = _timed_routes(feed.routes, timed)  # type: ignore[method-assign]
            station = Station(
                StationConfig(port=0, voice=False), fleet, link=link, assistant=None, feed=feed
            ).start()
            page = feed.subscribe()
            draining = threading.Event()

            def drain() -> None:
                while not draining.is_set():
                    page.take(0.05)
                    time.sleep(1 / 60)

            drainer = threading.Thread(target=drain, daemon=True)
            drainer.start()
            ready, sent = context.Event(), context.Queue()
            process = context.Process(target=publisher, args=(port, things, args, ready, sent))
            process.start()
            results = []
            try:
                time.sleep(1.0)
                ready.set()
                for _ in range(args.bursts):
                    times = sent.get(timeout=120)
                    if args.held:
                        time.sleep(1.0)  # the last publishes reach the broker
                    before = cpu_s()
                    release_at[0] = time.time() * 1000
                    released.set()
                    if not done.wait(120):
                        raise RuntimeError(f"a burst of {per_burst} messages did not all arrive")
                    done.clear()
                    spent = cpu_s() - before
                    latencies = [taken[t] - at for t, at in times.items() if t in taken]
                    first = release_at[0] if args.held else min(times.values())
                    last = max(taken[t] for t in times) - first
                    results.append(
                        {
                            "p50": percentile(latencies, 50),
                            "p95": percentile(latencies, 95),
                            "max": max(latencies),
                            "drain": last,
                            "cpu_us": spent / per_burst * 1e6,
                            "taken_us": last / per_burst * 1e3,
                        }
                    )
            finally:
                process.join(60)
                draining.set()
                drainer.join(5)
                station.stop()
                link.stop()
    summary = {
        "robots": args.robots,
        "messages_per_burst": per_burst,
        "document_p50_ms": round(median([r["p50"] for r in results]), 1),
        "document_p95_ms": round(median([r["p95"] for r in results]), 1),
        "document_max_ms": round(median([r["max"] for r in results]), 1),
        "burst_taken_ms": round(median([r["drain"] for r in results]), 1),
        "station_cpu_us_per_message": round(median([r["cpu_us"] for r in results]), 1),
        "held": args.held,
        "burst_taken_us_per_message": round(median([r["taken_us"] for r in results]), 1),
        "load": list(os.getloadavg()),
    }
    print(json.dumps(summary))
    return 0


def _timed_routes(routes: Any, timed: Any) -> Any:
    def wrapped(*, turns: bool) -> Any:
        return [(f, timed(h)) for f, h in routes(turns=turns)]

    return wrapped


if __name__ == "__main__":
    raise SystemExit(main())
