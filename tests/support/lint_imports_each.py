"""Run `lint-imports` once per change, all in one interpreter: a script for the layer tests.

Usage: `python tests/support/lint_imports_each.py CONFIG < changes.json`, from the directory
holding a copy of the packages (and with it as PYTHONPATH). `changes.json` is a list of
`[module path, line]`; for each, the line is appended to the module, the check is run through
import-linter's own entry point (`importlinter.cli.lint_imports`, what the `lint-imports`
command calls), and the module is put back. Printed: a JSON list of `{"exit": code, "report":
text}`, one per change, in order.

One interpreter for all the changes, rather than a `lint-imports` process each: the check
itself takes a quarter of a second, a process of its own three times that.
"""

from __future__ import annotations

import contextlib
import io
import json
import sys
from pathlib import Path

from importlinter.cli import lint_imports


def check(config: str) -> dict[str, object]:
    printed = io.StringIO()
    with contextlib.redirect_stdout(printed):
        code = lint_imports(config_filename=config, no_cache=True, no_logo=True)
    return {"exit": code, "report": printed.getvalue()}


def main() -> None:
    config = sys.argv[1]
    outcomes = []
    for module, line in json.load(sys.stdin):
        path = Path(module)
        source = path.read_text()
        path.write_text(source + f"\n{line}  # noqa\n")
        try:
            outcomes.append(check(config))
        finally:
            path.write_text(source)
    json.dump(outcomes, sys.stdout)


if __name__ == "__main__":
    main()
