"""`robot-agent`: run a robot or a swarm, provision credentials, and use the voice alone."""

from __future__ import annotations

from typing import TYPE_CHECKING

from vahr.cli_router import Subcommands, dispatch

if TYPE_CHECKING:
    from collections.abc import Sequence

SUBCOMMANDS: Subcommands = {
    "run": ("robot_agent.commands.run", "run one robot: receive commands, drive, report state"),
    "swarm": (
        "robot_agent.commands.swarm",
        "run many simulated robots of a fleet in one process, on one connection",
    ),
    "provision": ("robot_agent.commands.provision", "create a robot's certificate, key and config"),
    "speak": ("robot_agent.commands.speak", "render text to a WAV file with the robot's voice"),
    "hear": (
        "robot_agent.commands.hear",
        "hear an answer in a WAV file; make or score the spoken evaluation set",
    ),
}


def main(argv: Sequence[str] | None = None) -> int:
    return dispatch("robot-agent", __doc__ or "", SUBCOMMANDS, argv)


if __name__ == "__main__":
    raise SystemExit(main())
