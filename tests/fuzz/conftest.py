"""Hypothesis profiles and the tally of the fuzz tests.

`make test` runs the `ci` profile: a small budget, derandomized (the same inputs every run,
no example database), so a failure is reproducible and no run is slower than the last; it
reports a failing input as found, without shrinking it (shrinking an input that goes
through a broker can take minutes). `VAHR_FUZZ_PROFILE=debug` shrinks it to the smallest.
`bench/fuzz.py` selects the `bench` profile (`VAHR_FUZZ_PROFILE=bench`): at least 10,000
generated inputs per boundary, also derandomized, and writes the tally to
`VAHR_FUZZ_REPORT` for docs/reliability.md.
"""

from __future__ import annotations

import json
import os
from pathlib import Path
from typing import TYPE_CHECKING

from hypothesis import HealthCheck, Phase, settings

from tests.fuzz.tally import TALLY

if TYPE_CHECKING:
    import pytest

COMMON = {
    "derandomize": True,
    "database": None,
    "deadline": None,
    "print_blob": True,
    "suppress_health_check": [HealthCheck.too_slow, HealthCheck.function_scoped_fixture],
}
NO_SHRINK = [Phase.explicit, Phase.generate]
settings.register_profile("ci", max_examples=100, phases=NO_SHRINK, **COMMON)  # type: ignore[arg-type]
settings.register_profile("debug", max_examples=100, **COMMON)  # type: ignore[arg-type]
settings.register_profile("bench", max_examples=10_000, phases=NO_SHRINK, **COMMON)  # type: ignore[arg-type]
settings.load_profile(os.environ.get("VAHR_FUZZ_PROFILE", "ci"))


def pytest_sessionfinish(session: pytest.Session, exitstatus: int) -> None:
    report = os.environ.get("VAHR_FUZZ_REPORT")
    if report:
        Path(report).write_text(json.dumps(TALLY.snapshot(), indent=2) + "\n")
