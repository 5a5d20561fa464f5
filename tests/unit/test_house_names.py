"""A file's name says what is in it: no module name is used three times or more across the
repository, so a reader who finds `room.py` or `station.py` knows which one is meant. The
names every package of a kind has (`__init__`, `conftest`, and a Lambda function's `app`,
`config` and `errors`) are the exception: their directory says whose they are."""

from __future__ import annotations

import subprocess
from collections import Counter
from pathlib import Path, PurePosixPath

ROOT = Path(__file__).resolve().parents[2]
CONVENTIONAL = {"__init__.py", "conftest.py", "app.py", "config.py", "errors.py"}


def module_names() -> Counter[str]:
    listed = subprocess.run(
        ["git", "ls-files", "*.py"], cwd=ROOT, capture_output=True, text=True, check=True
    ).stdout.split()
    return Counter(PurePosixPath(path).name for path in listed)


def test_no_module_name_is_used_three_times() -> None:
    crowded = {
        name: count
        for name, count in module_names().items()
        if count >= 3 and name not in CONVENTIONAL
    }
    assert not crowded, f"rename these so each says what it holds: {crowded}"


def test_the_fallback_intent_is_named_once() -> None:
    # Given every product module
    sources = [*ROOT.glob("vahr/**/*.py"), *ROOT.glob("lambda/**/*.py")]
    # Then Alexa's fallback intent is spelled in one place and imported everywhere else
    spelled = [
        path.relative_to(ROOT).as_posix()
        for path in sources
        if '"AMAZON.FallbackIntent"' in path.read_text(encoding="utf-8")
    ]
    assert spelled == ["vahr/domain/invocation.py"]
