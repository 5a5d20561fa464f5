"""`python -m vahr.skill_model`: regenerate the skill's files, or with `--check` report drift."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from vahr.domain import DEFAULT_FLEET_FILE, Fleet
from vahr.errors import VahrError
from vahr.protocol import ProtocolError
from vahr.skill_model.generator import drift, write

# In a checkout the bundled fleet is a link to the repository's fleet.yaml, at its root.
DEFAULT_ROOT = Path(DEFAULT_FLEET_FILE).resolve().parent


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog="python -m vahr.skill_model",
        description=(
            "Write skill-package/ (skill.json, the interaction model of en-US and of each "
            "locale with templates) and "
            "lambda/skill/fleet.json from fleet.yaml and the skill's intent definitions."
        ),
    )
    parser.add_argument(
        "--fleet",
        type=Path,
        default=Path(DEFAULT_FLEET_FILE).resolve(),
        help="fleet file (default: %(default)s)",
    )
    parser.add_argument(
        "--root",
        type=Path,
        default=DEFAULT_ROOT,
        help="repository root to write under (default: %(default)s)",
    )
    parser.add_argument(
        "--check", action="store_true", help="write nothing; exit 1 if any file would change"
    )
    args = parser.parse_args(argv)
    try:
        try:
            source = args.fleet.read_bytes()
        except OSError as err:
            raise VahrError(f"fleet: cannot read {args.fleet}: {err.strerror}") from err
        fleet = Fleet.from_yaml(source)
        if args.check:
            stale = drift(args.root, fleet, source)
            for path in stale:
                print(f"{path} is out of date with {args.fleet}", file=sys.stderr)
            if stale:
                print(
                    "run `make skill-model` (python -m vahr.skill_model) and commit",
                    file=sys.stderr,
                )
                return 1
            print("the skill package is up to date")
            return 0
        changed = write(args.root, fleet, source)
    except (VahrError, ProtocolError) as err:
        print(f"python -m vahr.skill_model: error: {err}", file=sys.stderr)
        return 2
    for path in changed:
        print(f"wrote {path}")
    if not changed:
        print("the skill package is up to date")
    return 0


if __name__ == "__main__":
    sys.exit(main())
