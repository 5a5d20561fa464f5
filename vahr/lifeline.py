"""Exec a command that dies with the process that started it (Linux `PR_SET_PDEATHSIG`).

Run as a script: `python -I -S lifeline.py PARENT_PID SIGNAL -- COMMAND [ARG...]`, the
command line `lifeline_command` writes. The lab side's children start through it
(`vahr.plumbing.lifetime`), and so do the robot's long batch tools (sphinxtrain, in
`robot_agent.voice.adaptation`); it sits at the top of the `vahr` package so that both may
use it. It arms the parent-death signal, checks that the parent is still the
process that asked (it may have died between fork and `prctl`, and then nothing would ever
send the signal), and replaces itself with COMMAND. The signal survives `exec`, so COMMAND
gets SIGNAL the moment its parent dies, SIGKILL of the parent included.

Doing this in a fresh single-threaded interpreter is what makes it safe: the alternative,
`preexec_fn`, runs Python between fork and exec in a copy of a threaded process, where a
lock held by another thread at fork time is never released. It imports nothing of VAHR so
it starts in a few milliseconds.
"""

from __future__ import annotations

import ctypes
import os
import sys

PR_SET_PDEATHSIG = 1
# Exit codes of the wrapper itself (the command's own codes follow the exec).
USAGE = 64
ORPHANED = 65
CANNOT_ARM = 66
CANNOT_EXEC = 127


def lifeline_command(command: list[str], death_signal: int) -> list[str]:
    """`command` prefixed with this wrapper, tied to the calling process's life (to the
    thread that forks it, strictly: see `vahr.plumbing.lifetime`)."""
    # os.path, not pathlib: the wrapper imports as little as it can, it starts every child.
    return [
        sys.executable, "-I", "-S", os.path.abspath(__file__),  # noqa: PTH100
        str(os.getpid()), str(int(death_signal)), "--", *command,
    ]  # fmt: skip


def main(argv: list[str]) -> int:
    if len(argv) < 5 or argv[3] != "--":
        print("usage: lifeline.py PARENT_PID SIGNAL -- COMMAND [ARG...]", file=sys.stderr)
        return USAGE
    parent, signal_number, command = int(argv[1]), int(argv[2]), argv[4:]
    if sys.platform != "linux":
        # No parent-death signal elsewhere: the command runs, without the guarantee.
        return _exec(command)
    libc = ctypes.CDLL(None, use_errno=True)
    if libc.prctl(PR_SET_PDEATHSIG, signal_number, 0, 0, 0) != 0:
        print(f"lifeline: prctl: {os.strerror(ctypes.get_errno())}", file=sys.stderr)
        return CANNOT_ARM
    if os.getppid() != parent:
        # The parent died before the signal was armed: do not start an orphan.
        return ORPHANED
    return _exec(command)


def _exec(command: list[str]) -> int:
    try:
        os.execvp(command[0], command)
    except OSError as err:
        print(f"lifeline: cannot run {command[0]}: {err.strerror}", file=sys.stderr)
    return CANNOT_EXEC


if __name__ == "__main__":
    sys.exit(main(sys.argv))
