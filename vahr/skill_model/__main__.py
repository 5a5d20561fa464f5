"""`python -m vahr.skill_model`: regenerate skill-package/, or with `--check` report drift."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from vahr.errors import VahrError
from vahr.protocol import DEFAULT_FLEET_FILE, ProtocolError, load_fleet
from vahr.skill_model.generator import drift, write

DEFAULT_PACKAGE_DIR = Path(DEFAULT_FLEET_FILE).parent / "skill-package"


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog="python -m vahr.skill_model",
        description="Write skill-package/ from fleet.yaml and the skill's intent definitions.",
    )
    parser.add_argument(
        "--fleet", default=DEFAULT_FLEET_FILE, help="fleet file (default: %(default)s)"
    )
    parser.add_argument(
        "--out",
        type=Path,
        default=DEFAULT_PACKAGE_DIR,
        help="skill package folder (default: %(default)s)",
    )
    parser.add_argument(
        "--check", action="store_true", help="write nothing; exit 1 if any file would change"
    )
    args = parser.parse_args(argv)
    try:
        fleet = load_fleet(args.fleet)
        if args.check:
            stale = drift(args.out, fleet)
            for path in stale:
                print(f"{path} is out of date with {args.fleet}", file=sys.stderr)
            if stale:
                print(
                    "run `make skill-model` (python -m vahr.skill_model) and commit",
                    file=sys.stderr,
                )
                return 1
            print(f"{args.out} is up to date")
            return 0
        changed = write(args.out, fleet)
    except (VahrError, ProtocolError) as err:
        print(f"python -m vahr.skill_model: error: {err}", file=sys.stderr)
        return 2
    for path in changed:
        print(f"wrote {path}")
    if not changed:
        print(f"{args.out} is up to date")
    return 0


if __name__ == "__main__":
    sys.exit(main())
