"""A small command-line dispatcher shared by `vahr` and `robot-agent`.

Each subcommand lives in its own module exposing `configure(parser)` and `run(args) -> int`.
Only the module of the subcommand being run is imported, so `robot-agent run` does not pay
for the report's plotting libraries, nor `vahr say` for the simulator.
"""

from __future__ import annotations

import argparse
import importlib
import logging
import sys
from typing import TYPE_CHECKING

from vahr.errors import VahrError
from vahr.protocol import ProtocolError

if TYPE_CHECKING:
    from collections.abc import Callable, Sequence

Subcommands = dict[str, tuple[str, str]]  # name -> (module, one-line help)


def dispatch(
    prog: str, description: str, subcommands: Subcommands, argv: Sequence[str] | None
) -> int:
    """Parse `argv`, run the chosen subcommand, and turn user errors into one line."""
    args_in = list(sys.argv[1:] if argv is None else argv)
    parser = argparse.ArgumentParser(prog=prog, description=description)
    commands = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    for name, (module_name, help_text) in subcommands.items():
        sub = commands.add_parser(name, help=help_text, description=help_text)
        if args_in and args_in[0] == name:
            module = importlib.import_module(module_name)
            module.configure(sub)
            sub.set_defaults(run=module.run)
    args = parser.parse_args(args_in)
    run: Callable[[argparse.Namespace], int] = args.run
    try:
        return run(args)
    except (VahrError, ProtocolError) as err:
        print(f"{prog} {args.command}: error: {err}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        return 130


def add_logging_flag(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--log-level",
        default="INFO",
        choices=["DEBUG", "INFO", "WARNING", "ERROR"],
        help="how much to log (default: INFO)",
    )


# Libraries whose INFO lines are no news to a person ("Found credentials in environment
# variables" on every skill start): heard from at WARNING unless everything is asked for.
QUIET_LIBRARIES = ("botocore", "boto3", "urllib3")


def setup_logging(level: str) -> None:
    logging.basicConfig(
        level=level, format="%(asctime)s %(levelname)s %(name)s: %(message)s", stream=sys.stderr
    )
    if level != "DEBUG":
        for name in QUIET_LIBRARIES:
            logging.getLogger(name).setLevel(max(logging.WARNING, logging.getLevelName(level)))
