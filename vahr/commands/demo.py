"""`vahr demo`: the paper's scenario end to end on this machine, with its latencies.

Starts the whole system on free ports in a temporary state directory (simulated time runs
faster so the scenario takes well under a minute), speaks a scripted conversation, waits
for the robots to finish what each line asked, prints every exchange with its latency,
then has a simulated participant perform the paper's tasks I-III with both methods and
prints the judge's verdicts and the HRI metrics, then the billable operations the data
plane counted, and stops everything.
"""

from __future__ import annotations

import json
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from vahr.cli_router import add_logging_flag, setup_logging
from vahr.commands.fleet_flag import add_fleet_flag, read_fleet

if TYPE_CHECKING:
    import argparse

    from vahr.domain import Fleet

WAIT_TIMEOUT_S = 30.0


@dataclass(frozen=True)
class Step:
    """One line of the script, and what must happen for it to count as done."""

    utterance: str
    # Each (thing, event) must be seen for the step's command before the next line.
    until: tuple[tuple[str, str], ...] = ()
    voice: bool = False  # needs the room assistant


# The paper's scenario. Each name in braces is said as the fleet run says it (`script_for`):
# {first} and {second} are its first two robots (and, in `until`, their things), {all} and
# {everyone} the whole fleet, {LOADING}, {A}, {C} and {D} those zones, and {B} a zone to
# drive to (B when the fleet has one).
SCRIPT = (
    Step("Alexa, open robot fleet"),
    Step("send {first} to {B}", until=(("first", "arrived"),)),
    Step("send {all} to {LOADING}", until=(("first", "arrived"), ("second", "arrived"))),
    Step("where is {second}"),
    Step("have {second} deliver a package to {D}", until=(("second", "delivered"),)),
    Step(
        "{first} deliver to {A} then {second} deliver to {C}",
        until=(("first", "delivered"), ("second", "delivered")),
    ),
    Step("send {everyone} to {B}"),
    Step("emergency stop", until=(("first", "stopped"), ("second", "stopped"))),
    Step(
        "have {first} deliver based on the weather",
        until=(("first", "delivered"),),
        voice=True,
    ),
    Step("where are the robots"),
    Step("exit"),
)  # fmt: skip
# What the script calls each part of the paper's fleet; a fleet without such a name is
# called by its first spoken name.
PAPER_NAMES = {
    "first": "robot one", "second": "robot two", "all": "all robots", "everyone": "everyone",
    "LOADING": "the loading zone", "A": "zone a", "B": "zone b", "C": "zone c", "D": "zone d",
}  # fmt: skip


def script_for(fleet: Fleet) -> list[Step]:
    """The scenario in the fleet's names, for a fleet fit for the paper's tasks."""
    from vahr.domain import FLEET_GROUP, FLEET_GROUP_NAMES

    def said(role: str, spoken: list[str] | tuple[str, ...]) -> str:
        return PAPER_NAMES[role] if PAPER_NAMES[role] in spoken else spoken[0]

    first, second = fleet.robots[0], fleet.robots[1]
    group = next((g.spoken for g in fleet.groups if g.id == FLEET_GROUP), FLEET_GROUP_NAMES)
    elsewhere = [z.id for z in fleet.zones if z.id not in ("LOADING", "A", "C", "D")]
    zones = {zone_id: fleet.zone(zone_id) for zone_id in ("LOADING", "A", "C", "D")}
    zones["B"] = fleet.zone("B" if "B" in fleet.zone_ids else (elsewhere or ["A"])[0])
    names = {
        "first": said("first", first.spoken),
        "second": said("second", second.spoken),
        "all": said("all", group),
        "everyone": said("everyone", group),
        **{role: said(role, zone.spoken) for role, zone in zones.items()},
    }
    things = {"first": first.thing, "second": second.thing}
    return [
        Step(
            step.utterance.format(**names),
            tuple((things[role], kind) for role, kind in step.until),
            step.voice,
        )
        for step in SCRIPT
    ]


def configure(parser: argparse.ArgumentParser) -> None:
    add_fleet_flag(parser)
    parser.add_argument(
        "--sim-speed-factor", type=float, default=20.0, help="simulated time speed-up (20)"
    )
    parser.add_argument("--no-voice", action="store_true", help="skip the spoken weather task")
    parser.add_argument(
        "--no-experiment", action="store_true", help="skip the paper's tasks I-III (simulated)"
    )
    parser.add_argument("--json", action="store_true", help="print one JSON object per exchange")
    add_logging_flag(parser)
    parser.set_defaults(log_level="WARNING")


class _Events:
    """Robot events seen on the broker, to wait for what a command should cause."""

    def __init__(self) -> None:
        import threading

        self.seen: list[tuple[str, str, str | None]] = []
        self._changed = threading.Condition()

    def record(self, event: Any) -> None:
        with self._changed:
            self.seen.append((event.thing, event.event, event.command_id))
            self._changed.notify_all()

    def wait(self, commands: list[str], wanted: tuple[tuple[str, str], ...]) -> list[str]:
        """Wait for each (thing, event) of one of `commands`; return what was missing."""
        deadline = time.monotonic() + WAIT_TIMEOUT_S
        with self._changed:
            while True:
                missing = [
                    f"{thing} {kind}"
                    for thing, kind in wanted
                    if not any(t == thing and k == kind and c in commands for t, k, c in self.seen)
                ]
                remaining = deadline - time.monotonic()
                if not missing or remaining <= 0:
                    return missing
                self._changed.wait(remaining)


def run(args: argparse.Namespace) -> int:
    from vahr.errors import VahrError
    from vahr.experiment.tasks import require_fit_fleet
    from vahr.local.system import LocalSystem, SystemConfig
    from vahr.plumbing.ports import free_port

    setup_logging(args.log_level)
    fleet = read_fleet(args.fleet)
    # The script and the experiment use the paper's zones and two robots: checked first.
    require_fit_fleet(fleet)
    script = script_for(fleet)
    events = _Events()
    with tempfile.TemporaryDirectory(prefix="vahr-demo-") as state:
        config = SystemConfig(
            state_dir=Path(state),
            mqtts_port=free_port(),
            # The simulated participant's console publishes on the loopback dev listener.
            mqtt_port=free_port(),
            api_port=free_port(),
            fleet=fleet,
            sim_speed_factor=args.sim_speed_factor,
            voice=not args.no_voice,
            log_level=args.log_level,
            # The paper's one-turn commands: nothing is confirmed first.
            confirm=False,
        )
        started = time.perf_counter()
        with LocalSystem(config, on_event=events.record) as system:
            system.wait_ready()
            boot_s = time.perf_counter() - started
            if not args.json:
                print(
                    f"vahr demo: {', '.join(system.fleet.robot_things)} online "
                    f"after {boot_s:.1f} s; simulated time x{args.sim_speed_factor:g}\n"
                )
            assert system.alexa is not None and system.stack.dataplane is not None
            latencies: list[float] = []
            failures: list[str] = []
            for step in script:
                if step.voice and not system.voice_enabled:
                    continue
                turn = system.alexa.say(step.utterance)
                latencies.append(turn.latency_ms)
                missing = events.wait(turn.commands, step.until) if step.until else []
                _print_turn(step, turn.to_json(), missing, args.json)
                if missing:
                    failures.append(f"{step.utterance!r}: no {', '.join(missing)}")
            if not args.no_experiment:
                failures += _experiment(system, Path(state) / "experiment", args)
            meter = system.stack.meter.snapshot()
        total_s = time.perf_counter() - started
    _print_summary(latencies, meter, total_s, args.json)
    if failures:
        raise VahrError(f"the demo did not complete: {'; '.join(failures)}")
    return 0


def _experiment(system: Any, log_dir: Path, args: argparse.Namespace) -> list[str]:
    """The paper's tasks I-III, performed by the simulated participant with both methods."""
    from vahr.experiment.eventlog import read_log
    from vahr.experiment.live_session import run_simulated_session
    from vahr.experiment.metrics import fan_out, rad
    from vahr.experiment.results import row_from_log
    from vahr.plumbing.client import HttpAssistant

    if not args.json:
        print("The paper's experiment, tasks I-III (simulated participant):\n")
    failures: list[str] = []
    methods = ("vahr", "keyboard") if system.voice_enabled else ("keyboard",)
    for method in methods:
        verdict, log_path = run_simulated_session(
            fleet=system.fleet,
            method=method,
            log_dir=log_dir,
            broker_url=system.stack.mqtt_url,
            assistant=HttpAssistant(system.stack.api_url),
            participant="DEMO",
            seed=3,
            speed_factor=args.sim_speed_factor,
            data_plane_url=system.stack.api_url,
        )
        row = row_from_log(read_log(log_path))
        demand = rad(row.interaction_time_s, row.neglect_time_s)
        passed = {task: outcome.success for task, outcome in verdict.tasks.items()}
        result = {
            "method": method,
            "simulated": True,
            "tasks": passed,
            "interaction_time_s": round(row.interaction_time_s, 1),
            "neglect_time_s": round(row.neglect_time_s, 1),
            "time_taken_s": round(row.task_time_s, 1),
            "rad": round(demand, 3),
            "fan_out_s": round(fan_out(row.task_time_s, demand), 1),
        }
        failures += [
            f"{method} task {task}: {outcome.reason}"
            for task, outcome in verdict.tasks.items()
            if not outcome.success
        ]
        if args.json:
            print(json.dumps({"experiment": result}))
            continue
        tasks = ", ".join(f"{task} {'passed' if ok else 'FAILED'}" for task, ok in passed.items())
        print(
            f"  {method:8}  {tasks}\n            IE {result['interaction_time_s']} s, "
            f"NT {result['neglect_time_s']} s, time taken {result['time_taken_s']} s, "
            f"RAD {result['rad']}, fan-out {result['fan_out_s']} s\n"
        )
    return failures


def _print_turn(step: Step, turn: dict[str, Any], missing: list[str], as_json: bool) -> None:
    if as_json:
        print(json.dumps({"utterance": step.utterance, **turn, "missing": missing}))
        return
    print(f"  you    {step.utterance}")
    print(f"  alexa  {turn['speech'] or '(session closed)'}")
    outcome = (
        ""
        if not step.until
        else ("  (robots: done)" if not missing else f"  (missing: {', '.join(missing)})")
    )
    intent = turn["intent"] or turn["request_type"]
    print(f"         [{intent}, {turn['latency_ms']:.0f} ms]{outcome}\n")


def _print_summary(
    latencies: list[float], meter: dict[str, dict[str, int]], total_s: float, as_json: bool
) -> None:
    ordered = sorted(latencies)
    p50 = ordered[len(ordered) // 2] if ordered else 0.0
    summary = {
        "exchanges": len(latencies),
        "latency_ms_p50": round(p50, 1),
        "latency_ms_max": round(max(latencies, default=0.0), 1),
        "billable_operations": meter["operations"],
        "seconds": round(total_s, 1),
    }
    if as_json:
        print(json.dumps({"summary": summary}))
        return
    operations = ", ".join(f"{k} {v}" for k, v in sorted(meter["operations"].items()))
    print(
        f"{summary['exchanges']} exchanges; reply latency p50 {summary['latency_ms_p50']} ms, "
        f"max {summary['latency_ms_max']} ms; {summary['seconds']} s in all"
    )
    print(f"AWS operations counted by the local data plane: {operations}")
