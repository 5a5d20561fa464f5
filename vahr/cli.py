"""`vahr`: run the whole system on this machine, talk to it, and run the experiment."""

from __future__ import annotations

from typing import TYPE_CHECKING

from vahr.cli_router import Subcommands, dispatch

if TYPE_CHECKING:
    from collections.abc import Sequence

SUBCOMMANDS: Subcommands = {
    "up": (
        "vahr.commands.up",
        "run the broker, shadows, data plane, Alexa simulator and the robots of a fleet file",
    ),
    "say": ("vahr.commands.say", "say an utterance to the running system as a person to Alexa"),
    "console": ("vahr.commands.console", "talk to the running system interactively"),
    "station": (
        "vahr.commands.station",
        "serve the operator station page (map, panel, push-to-talk) for any deployment",
    ),
    "audit": (
        "vahr.commands.audit",
        "print the audit trail of every command (who, channel, outcome) or verify it",
    ),
    "users": (
        "vahr.commands.users",
        "check a users file, load it into the users table on AWS, make a station token",
    ),
    "fault": (
        "vahr.commands.fault",
        "inject a fault (stuck, fail, offline, clear) into a running simulated robot",
    ),
    "nlu": ("vahr.commands.nlu", "show how an utterance is understood, without executing it"),
    "demo": ("vahr.commands.demo", "run the paper's scenario end to end on this machine"),
    "experiment": ("vahr.commands.experiment", "run one experiment session (tasks I-III)"),
    "tlx": ("vahr.commands.tlx", "record a participant's NASA-TLX answers for a session"),
    "report": (
        "vahr.commands.report",
        "turn experiment results into the paper's tables and figures",
    ),
    "rehearse": (
        "vahr.commands.rehearse",
        "run a whole simulated study and set it beside the paper's Table II",
    ),
}


def main(argv: Sequence[str] | None = None) -> int:
    return dispatch("vahr", __doc__ or "", SUBCOMMANDS, argv)


if __name__ == "__main__":
    raise SystemExit(main())
