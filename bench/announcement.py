"""A robot stuck, told to the operator: its stuck event to the station's alert painted.

`vahr up` (the broker, the robots as their own processes, the announcer and the station in
the stack's process) with one station page in headless Chromium (`?metrics=1`, clicked once
so that it may beep). Each sample makes one robot stuck with the development fault topic
(`POST /vahr/fault`, what `vahr fault THING stuck` does), sends it across the floor by
voice (`POST /vahr/say`), and measures, on this machine's clock:

- the robot's `stuck` event (or the `failed` that ends its task, whichever the broker
  carries first) reaching the broker, as this script's subscriber receives it;
- the announcement on `vahr/assistant/announcements`, as this script receives it;
- the page receiving it from the station's stream, and the alert painted (the page marks
  it after the frame it was drawn in).

The page then acknowledges it with a click. Samples are spaced so that the announcement
policy's rate limit (`max_per_window` in `window_s`, per person) never holds one back: its
delay is the policy's, not the path's, and the run checks it stays zero.
Target (issue 34): stuck event to alert painted, p95 at most 1 s.
Run: `.venv/bin/python bench/announcement.py [--samples 20] [--speed 10]`.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import tempfile
import threading
import time
from datetime import datetime
from pathlib import Path
from typing import Any

from _results import median, percentile, write_section

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from playwright.sync_api import sync_playwright  # noqa: E402

from tests.support.browser import launch  # noqa: E402
from tests.support.vahr_up import start_up, stop_up  # noqa: E402
from vahr.announce import AnnounceSettings  # noqa: E402
from vahr.domain import load_fleet
from vahr.plumbing.client import call  # noqa: E402
from vahr.plumbing.mqtt import MqttClient, MqttEndpoint  # noqa: E402
from vahr.plumbing.ports import free_port  # noqa: E402
from vahr.protocol import decode_event, topics
from vahr.protocol.announcements import decode_announcement  # noqa: E402
from vahr.protocol.broker import parse_broker_url  # noqa: E402

TARGET_MS = 1000.0
WAIT_S = 60.0
ZONES = ("A", "D")


class Broker:
    """When each robot's end of task and each announcement reached the broker (ms)."""

    def __init__(self) -> None:
        self.ended: dict[str, tuple[float, str]] = {}  # command id -> (ms, event)
        self.announced: list[dict[str, Any]] = []
        self._changed = threading.Condition()

    def on_event(self, topic: str, payload: bytes) -> None:
        at = time.time() * 1000
        event = decode_event(payload)
        if event.event in ("stuck", "failed") and event.command_id is not None:
            with self._changed:
                self.ended.setdefault(event.command_id, (at, event.event))
                self._changed.notify_all()

    def on_announcement(self, topic: str, payload: bytes) -> None:
        at = time.time() * 1000
        announcement = decode_announcement(payload)
        held = (announcement.time - announcement.opened_at).total_seconds() * 1000
        with self._changed:
            self.announced.append(
                {"id": announcement.id, "thing": announcement.thing, "kind": announcement.kind,
                 "at": at, "held_ms": held}
            )  # fmt: skip
            self._changed.notify_all()

    def wait(self, found: Any, what: str) -> Any:
        deadline = time.monotonic() + WAIT_S
        with self._changed:
            while not (result := found()):
                if not self._changed.wait(max(0.0, deadline - time.monotonic())):
                    raise RuntimeError(f"not within {WAIT_S:g} s: {what}")
            return result


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--samples", type=int, default=20)
    parser.add_argument("--speed", type=float, default=10.0, help="the robots' speed factor")
    args = parser.parse_args()
    settings = AnnounceSettings()
    # One announcement per slot of the rate limit, with a margin: never held back.
    spacing_s = settings.window_s / settings.max_per_window + 1.0
    fleet = load_fleet()
    robots = [(robot.thing, robot.spoken[0]) for robot in fleet.robots]
    broker = Broker()
    samples: list[dict[str, float]] = []
    with tempfile.TemporaryDirectory(prefix="vahr-announcement-bench-") as folder:
        up = start_up(
            Path(folder), "--station-port", str(free_port()),
            "--sim-speed-factor", f"{args.speed:g}", plaintext=True,
        )  # fmt: skip
        try:
            address = parse_broker_url(up.endpoints["mqtt"])
            with MqttClient(MqttEndpoint(host=address.host, port=address.port)) as link:
                link.subscribe(topics.ALL_EVENTS, broker.on_event)
                link.subscribe(topics.ASSISTANT_ANNOUNCEMENTS, broker.on_announcement)
                with sync_playwright() as playwright:
                    browser = launch(playwright)
                    try:
                        page = browser.new_page(viewport={"width": 1280, "height": 800})
                        page.goto(up.endpoints["station"] + "?metrics=1")
                        page.locator('#link-state[data-state="live"]').wait_for(timeout=30_000)
                        page.locator("#robots-title").click()
                        for index in range(args.samples):
                            started = time.monotonic()
                            thing, spoken = robots[index % len(robots)]
                            zone = ZONES[(index // len(robots)) % len(ZONES)]
                            samples.append(sample(up.endpoints, page, broker, thing, spoken, zone))
                            print(json.dumps({"sample": index, **samples[-1]}), flush=True)
                            time.sleep(max(0.0, spacing_s - (time.monotonic() - started)))
                        beeps = page.evaluate("() => window.vahrMetrics.beeps")
                    finally:
                        browser.close()
        finally:
            stop_up(up.process)
    report(args, samples, beeps, spacing_s)
    return 0


def sample(
    endpoints: dict[str, str], page: Any, broker: Broker, thing: str, spoken: str, zone: str
) -> dict[str, float]:
    """One robot made stuck on its way to `zone`: the times of its alert's path (ms)."""
    api = endpoints["api"]
    told = len(broker.announced)
    call(api, "POST", "/vahr/fault", {"thing": thing, "fault": "stuck"})
    turn = call(api, "POST", "/vahr/say", {"utterance": f"send {spoken} to zone {zone}"})
    [command] = turn["commands"]
    ended_at, ended_by = broker.wait(lambda: broker.ended.get(command), f"{thing} stuck")
    announcement = broker.wait(
        lambda: next((a for a in broker.announced[told:] if a["thing"] == thing), None),
        f"{thing}'s announcement",
    )
    shown = page.wait_for_function(
        "(id) => window.vahrMetrics.alerts.find((a) => a.id === id)",
        arg=announcement["id"],
        timeout=WAIT_S * 1000,
    ).json_value()
    alert = page.locator(f'.alert[data-key="{thing} stuck"]')
    alert.get_by_role("button", name="Acknowledge").click()
    alert.wait_for(state="detached", timeout=WAIT_S * 1000)
    return {
        "ended_by_stuck": float(ended_by == "stuck"),
        "announced_ms": announcement["at"] - ended_at,
        "received_ms": shown["received"] - ended_at,
        "painted_ms": shown["at"] - ended_at,
        "held_ms": announcement["held_ms"],
    }


def report(
    args: argparse.Namespace, samples: list[dict[str, float]], beeps: int, spacing_s: float
) -> None:
    if not samples:
        raise RuntimeError("no sample was measured")

    def spread(key: str) -> str:
        values = [s[key] for s in samples]
        return f"{median(values):.1f} / {percentile(values, 95):.1f} / {max(values):.1f} ms"

    painted = [s["painted_ms"] for s in samples]
    p95 = percentile(painted, 95)
    verdict = "met" if p95 <= TARGET_MS else "NOT met"
    settings = AnnounceSettings()
    held = max(s["held_ms"] for s in samples)
    stuck_first = sum(int(s["ended_by_stuck"]) for s in samples)
    rows = [
        ("stuck event on the broker to the alert painted, p50 / p95 / max", spread("painted_ms")),
        (f"the same, p95 (target at most {TARGET_MS:g} ms)", f"{p95:.1f} ms ({verdict})"),
        ("of which to the announcement on the broker (the announcer)", spread("announced_ms")),
        ("of which to the page's receipt (the station and its stream)", spread("received_ms")),
        ("samples (the first end of task the broker carried was `stuck`)",
         f"{len(samples)} ({stuck_first})"),
        ("longest from the fault's start to its announcement (the rate limit's delay)",
         f"{held:.0f} ms"),
        ("beeps the page played", str(beeps)),
        ("the machine's load average at the end, 1 / 5 / 15 min",
         " / ".join(f"{load:.1f}" for load in os.getloadavg())),
    ]  # fmt: skip
    table = "\n".join(f"| {name} | {value} |" for name, value in rows)
    limit = f"{settings.max_per_window} announcements in {settings.window_s:g} s"
    body = f"""
`vahr up` (its two robots as their own processes at speed factor {args.speed:g}, the
announcer and the station in the stack's process) and one station page in headless
Chromium (1280x800). Each sample makes a robot stuck (`POST /vahr/fault`, as `vahr fault
THING stuck`), sends it across the floor by voice (`POST /vahr/say`), times its alert, and
acknowledges it with a click. One sample every {spacing_s:g} s, so that the rate limit
({limit}) never holds one back. Times run from the robot's stuck event reaching the
broker, on this machine's one clock; the stack, the robots, the browser and this script
share its cores.

| measure | value |
| --- | --- |
{table}
"""
    write_section(
        "announcement", "Station alerts: a robot's stuck event to the alert painted", body
    )
    print(
        json.dumps(
            {"samples": len(samples), "paint_p50_ms": round(percentile(painted, 50), 1),
             "paint_p95_ms": round(p95, 1), "at": datetime.now().isoformat(timespec="seconds")}
        )
    )  # fmt: skip


if __name__ == "__main__":
    raise SystemExit(main())
