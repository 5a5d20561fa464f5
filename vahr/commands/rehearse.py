"""`vahr rehearse`: a whole simulated study, reported beside the paper's Table II.

Runs N simulated participants through both methods and T trials each
(`vahr.experiment.study`) against a running `vahr up` (`--api` and `--broker`), or on a
stack it starts itself on free ports, faster than real time by `--speed-factor` (the robots'
simulated time and the participant's clock run at the same factor; every metric is in
study seconds). Writes DIR/logs/, DIR/results.csv (the CSV `vahr report` reads),
DIR/report.json, DIR/report.md and the figures; prints the paper's Table II beside the
rehearsal's. Everything it writes or prints is labelled simulated.
"""

from __future__ import annotations

import json
import sys
import tempfile
import time
from pathlib import Path
from typing import TYPE_CHECKING, Any

from vahr.cli_router import add_logging_flag, setup_logging
from vahr.errors import VahrError

if TYPE_CHECKING:
    import argparse

    from vahr.domain import Fleet

DEFAULT_OUT = Path("out") / "rehearsal"
DEFAULT_SPEED = 30.0


def configure(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--participants", type=int, default=10, help="how many (default 10)")
    parser.add_argument("--trials", type=int, default=2, help="trials per method (default 2)")
    parser.add_argument(
        "--out", type=Path, default=DEFAULT_OUT, help=f"output directory (default {DEFAULT_OUT})"
    )
    parser.add_argument(
        "--api",
        default=None,
        help="a running `vahr up`'s api URL (with --broker); default: start a stack here",
    )
    parser.add_argument(
        "--broker", default=None, help="a running `vahr up`'s mqtt:// URL (with --api)"
    )
    parser.add_argument(
        "--fleet",
        type=Path,
        metavar="FILE",
        help="fleet file for the stack it starts (default: fleet.yaml); with --api, the "
        "running stack's fleet is used",
    )
    parser.add_argument(
        "--speed-factor",
        type=float,
        default=None,
        help="study seconds per wall second (default: with --api the running stack's "
        f"`vahr up --sim-speed-factor`, which it must equal; else {DEFAULT_SPEED:g})",
    )
    parser.add_argument("--seed", type=int, default=1, help="the study's seed (default 1)")
    parser.add_argument(
        "--monitoring",
        choices=["glance", "watch", "announce"],
        default="glance",
        help="how participants monitor a robot they wait for: a glance at each puzzle "
        "part's end (the model, default), eyes on the screen until it happens "
        "(a sensitivity variant), or no looking at all, acting on the assistant's "
        "announcements of finished tasks",
    )
    parser.add_argument(
        "--task-timeout",
        type=float,
        default=600.0,
        help="study seconds after which a task ends undecided (default 600)",
    )
    parser.add_argument("--json", action="store_true", help="print report.json to stdout")
    add_logging_flag(parser)
    parser.set_defaults(log_level="WARNING")


def _check(args: argparse.Namespace) -> None:
    if args.participants < 1 or args.trials < 1:
        raise VahrError("--participants and --trials must be 1 or more")
    if args.speed_factor is not None and not args.speed_factor > 0:
        raise VahrError("--speed-factor must be more than 0")
    if args.task_timeout <= 0:
        raise VahrError("--task-timeout must be more than 0")
    if (args.api is None) != (args.broker is None):
        raise VahrError("--api and --broker go together (a running `vahr up`'s endpoints)")
    if args.api is not None and args.fleet is not None:
        raise VahrError(
            "--fleet is for the stack rehearse starts; with --api it rehearses on the running "
            "stack's fleet (give --fleet to that `vahr up`)"
        )


def speed_factor(api: str | None, asked: float | None) -> float:
    """The factor to rehearse at: a running stack's own (its `GET /vahr/health` tells it),
    which `asked` must equal; without a stack, `asked` or the default.

    A rehearsal at another factor than its robots' runs without a word and measures task
    times off by the ratio (x1 robots under a x30 participant: some 1,800 study seconds).
    """
    if api is None:
        return asked if asked is not None else DEFAULT_SPEED
    from vahr.plumbing.client import call

    running = call(api, "GET", "/vahr/health").get("sim_speed_factor")
    if not isinstance(running, int | float) or running <= 0:
        if asked is None:
            raise VahrError(
                f"{api} does not tell its robots' speed factor; give --speed-factor (it must "
                "equal the robots' --sim-speed-factor)"
            )
        return asked
    if asked is not None and asked != running:
        raise VahrError(
            f"--speed-factor {asked:g} differs from the running stack's x{running:g} "
            f"(vahr up --sim-speed-factor {running:g}): drop --speed-factor to adopt it"
        )
    return float(running)


def run(args: argparse.Namespace) -> int:
    from vahr.commands.fleet_flag import fleet_for
    from vahr.experiment.study import StudySpec, run_study
    from vahr.experiment.tasks import require_fit_fleet

    _check(args)
    setup_logging(args.log_level)
    args.speed_factor = speed_factor(args.api, args.speed_factor)
    # The running stack's fleet with --api, else the file's: checked before anything starts.
    fleet = fleet_for(args.fleet, args.api)
    require_fit_fleet(fleet)
    spec = StudySpec(
        participants=args.participants,
        trials=args.trials,
        out_dir=args.out,
        speed_factor=args.speed_factor,
        seed=args.seed,
        task_timeout_s=args.task_timeout,
        monitoring=args.monitoring,
    )

    def announce(line: str) -> None:
        print(f"[simulated] {line}", file=sys.stderr, flush=True)

    started = time.monotonic()
    if args.api is not None:
        report = run_study(spec, fleet, broker_url=args.broker, api_url=args.api, announce=announce)
    else:
        report = _on_own_stack(spec, fleet, args, announce)
    _print(report, args, time.monotonic() - started)
    return 0


def _on_own_stack(
    spec: Any, fleet: Fleet, args: argparse.Namespace, announce: Any
) -> dict[str, Any]:
    from vahr.experiment.study import run_study
    from vahr.local.system import LocalSystem, SystemConfig
    from vahr.plumbing.ports import free_port

    with tempfile.TemporaryDirectory(prefix="vahr-rehearse-") as state:
        config = SystemConfig(
            state_dir=Path(state),
            mqtts_port=free_port(),
            mqtt_port=free_port(),  # the participant's panel publishes on the loopback listener
            api_port=free_port(),
            fleet=fleet,
            sim_speed_factor=args.speed_factor,
            voice=True,
            log_level=args.log_level,
            # The paper's one-turn commands: nothing is confirmed first.
            confirm=False,
        )
        with LocalSystem(config) as system:
            if not system.voice_enabled:
                raise VahrError(
                    "the voice method needs the room assistant (espeak-ng); "
                    "install it or rehearse against a running `vahr up`"
                )
            system.wait_ready()
            announce(f"stack up: {', '.join(system.fleet.robot_things)} at x{args.speed_factor:g}")
            assert system.stack.mqtt_url is not None
            return run_study(
                spec,
                system.fleet,
                broker_url=system.stack.mqtt_url,
                api_url=system.stack.api_url,
                announce=announce,
            )


def _print(report: dict[str, Any], args: argparse.Namespace, wall_s: float) -> None:
    from vahr.experiment.paper import render_comparison

    if args.json:
        print(json.dumps(report))
        return
    print(
        f"Simulated study: {report['participants']} participants x {len(report['trials'])} "
        f"trial(s) x {len(report['methods'])} methods, speed x{args.speed_factor:g}, "
        f"monitoring by {args.monitoring}, "
        f"{wall_s:.0f} s of wall time. SIMULATED participants, not people.\n"
    )
    print(render_comparison(report["paper_comparison"]))
    print(f"written to {args.out}: report.md, report.json, results.csv, figures, logs/")
