"""`vahr experiment`: run one session of the paper's experiment (tasks I-III).

Draws (or, when the session's log exists, resumes) the plan, writes it to the experiment
thing's shadow, records the wire into the session's event log, and runs the tasks with a
person and an observer, or with the simulated participant (`--simulate`).
"""

from __future__ import annotations

import json
import sys
from pathlib import Path
from typing import TYPE_CHECKING, Any

from vahr.commands.broker_flags import add_broker_flags, client_credentials
from vahr.commands.fleet_flag import add_fleet_flag, fleet_for
from vahr.errors import VahrError

if TYPE_CHECKING:
    import argparse

DEFAULT_LOG_DIR = Path(".state") / "experiment"


def configure(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--participant", required=True, help="participant id, e.g. P01")
    parser.add_argument(
        "--method",
        required=True,
        choices=["vahr", "keyboard"],
        help="voice through the assistant, or keyboard and mouse",
    )
    parser.add_argument("--trial", required=True, type=int, help="trial number (1, 2, ...)")
    parser.add_argument(
        "--seed",
        type=int,
        default=None,
        help="seed of the zone assignments and weather "
        "(default: derived from participant, method and trial)",
    )
    parser.add_argument(
        "--log-dir",
        type=Path,
        default=DEFAULT_LOG_DIR,
        help=f"where session logs live (default: {DEFAULT_LOG_DIR})",
    )
    add_fleet_flag(parser, beside_a_stack=True)
    add_broker_flags(
        parser,
        purpose="to record from and send console commands to",
        default="mqtt://127.0.0.1:1883",
    )
    parser.add_argument(
        "--api",
        default=None,
        help="data-plane API URL (`vahr up`'s api) for the experiment shadow "
        "and the assistant; default: AWS_ENDPOINT_URL_IOT_DATA_PLANE or AWS",
    )
    parser.add_argument(
        "--no-shadow",
        action="store_true",
        help="do not write the plan to the experiment thing's shadow",
    )
    parser.add_argument(
        "--simulate",
        action="store_true",
        help="the simulated participant performs the tasks (labelled simulated)",
    )
    parser.add_argument(
        "--speed-factor",
        type=float,
        default=1.0,
        help="with --simulate: run this many times faster than real time "
        "(match the simulated robots' factor)",
    )
    parser.add_argument(
        "--task-timeout",
        type=float,
        default=600.0,
        help="experiment seconds after which a task ends undecided (default 600)",
    )
    parser.add_argument(
        "--pause",
        type=float,
        default=0.0,
        help="experiment seconds between tasks, as the floor is reset (default 0)",
    )
    parser.add_argument(
        "--plan-only", action="store_true", help="draw and publish the plan, print it, and stop"
    )
    parser.add_argument("--json", action="store_true", help="print the result as JSON")


def run(args: argparse.Namespace) -> int:
    from vahr.experiment.session import SessionSpec, open_session
    from vahr.experiment.tasks import default_seed, require_fit_fleet

    if args.speed_factor <= 0 or (args.speed_factor != 1.0 and not args.simulate):
        raise VahrError("--speed-factor must be > 0 and is only for --simulate")
    if args.task_timeout <= 0:
        raise VahrError("--task-timeout must be > 0")
    if args.pause < 0:
        raise VahrError("--pause must be >= 0")
    fleet = fleet_for(args.fleet, args.api)
    # Before the session's log is opened: a fleet the tasks cannot run on leaves nothing.
    require_fit_fleet(fleet)
    seed = (
        args.seed
        if args.seed is not None
        else default_seed(args.participant, args.method, args.trial)
    )
    spec = SessionSpec(
        participant=args.participant,
        method=args.method,
        trial=args.trial,
        seed=seed,
        log_dir=args.log_dir,
        simulated=args.simulate,
        speed_factor=args.speed_factor,
        task_timeout_s=args.task_timeout,
        pause_s=args.pause,
    )
    session = open_session(spec, fleet)
    try:
        plan = session.plan
        if not args.no_shadow:
            from vahr.experiment.experiment_shadow import ExperimentShadow

            ExperimentShadow(fleet, endpoint_url=args.api).write(plan.experiment_state(spec.name))
        summary: dict[str, Any] = {
            "session": spec.name,
            "log": str(spec.path),
            "resumed": session.resumed,
            "simulated": args.simulate,
            "plan": plan.to_json(),
        }
        if not args.json:
            _show_plan(spec.name, plan.to_json(), session.resumed, args.method)
        if not args.plan_only:
            summary["verdict"] = _run_session(args, fleet, session).to_json()
        if args.json:
            print(json.dumps(summary))
    finally:
        session.log.close()
    return 0


def _show_plan(name: str, plan: dict[str, Any], resumed: bool, method: str) -> None:
    print(f"session {name}{' (resumed)' if resumed else ''}, seed {plan['seed']}")
    for thing, zone in plan["assignments"].items():
        print(f"  task I: {thing} delivers to zone {zone}")
    if method == "keyboard":
        print("  task II: ask the assistant for the weather for each robot, then deliver")
    else:
        print("  task II: each robot asks the assistant for the weather and delivers")
    print("  task III: both robots deliver to zone D, the first robot first")


def _run_session(args: argparse.Namespace, fleet: Any, session: Any) -> Any:
    from vahr.experiment.live_session import run_live, simulated_performer

    performer_for: Any
    if args.simulate:
        from vahr.plumbing.client import HttpAssistant, SayCommandAssistant

        assistant = HttpAssistant(args.api) if args.api else SayCommandAssistant(None)
        performer_for = simulated_performer(session, fleet, assistant)
    else:
        from vahr.experiment.observer import ObserverConsole

        def performer_for(console: Any) -> Any:
            return ObserverConsole(log=session.log, console=console)

    prefix = "[simulated] " if args.simulate else ""

    def announce(line: str) -> None:
        if not args.json:
            print(prefix + line, flush=True)

    tls = client_credentials(args)
    verdict = run_live(
        session,
        fleet,
        broker_url=args.broker,
        performer_for=performer_for,
        announce=announce,
        tls=tls,
    )
    if not args.json:
        for key, tally in (
            ("commands", verdict.commands),
            ("communication", verdict.communication),
            ("tasks", verdict.task_tally),
        ):
            print(f"{key}: {tally.successes}/{tally.total} succeeded")
        print(f"log: {session.spec.path}", file=sys.stderr)
    return verdict
