"""The exec wrapper that ties a child to its parent's life (vahr/lifeline.py)."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
from pathlib import Path

from vahr.lifeline import lifeline_command

LIFELINE = Path(lifeline_command([], 0)[3])  # the wrapper script itself


def test_the_command_runs_with_the_parent_death_signal_armed(tmp_path: Path) -> None:
    # The child asks the kernel for its own parent-death signal (PR_GET_PDEATHSIG).
    probe = (
        "import ctypes; v = ctypes.c_int(); "
        "ctypes.CDLL(None).prctl(2, ctypes.byref(v), 0, 0, 0); print(v.value)"
    )
    done = subprocess.run(
        lifeline_command([sys.executable, "-c", probe], signal.SIGTERM),
        capture_output=True, text=True, timeout=30, check=True,
    )  # fmt: skip
    assert done.stdout.strip() == str(int(signal.SIGTERM))


def test_a_parent_that_is_already_gone_starts_nothing(tmp_path: Path) -> None:
    marker = tmp_path / "ran"
    # Given a parent pid that is not this process's (as if the parent died before arming)
    done = subprocess.run(
        [sys.executable, "-I", "-S", str(LIFELINE), str(os.getpid() + 1_000_000), "9",
         "--", "touch", str(marker)],
        capture_output=True, timeout=30, check=False,
    )  # fmt: skip
    # Then the command never runs
    assert done.returncode == 65
    assert not marker.exists()


def test_a_wrong_call_is_a_usage_error() -> None:
    done = subprocess.run(
        [sys.executable, "-I", "-S", str(LIFELINE), "1"], capture_output=True, text=True,
        timeout=30, check=False,
    )  # fmt: skip
    assert done.returncode == 64
    assert done.stderr.startswith("usage: lifeline.py PARENT_PID SIGNAL -- COMMAND")
