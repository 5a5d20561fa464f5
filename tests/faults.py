"""Fault injection shared by the hardening tests and the long runs in `bench/`.

Each helper does one thing a real failure does (a process killed with SIGKILL, a broker
that crashes and comes back) and waits on a condition with a deadline, never a fixed sleep,
so the same helpers serve a two-minute test and a thirty-minute soak.
"""

from __future__ import annotations

import contextlib
import os
import signal
import time
from pathlib import Path
from typing import TYPE_CHECKING

from vahr.local.recovery import Leftover, started_for

if TYPE_CHECKING:
    from collections.abc import Callable

    from vahr.local.broker import Mosquitto


def alive(pid: int) -> bool:
    """True while `pid` runs (a zombie waiting to be reaped counts as gone)."""
    try:
        stat = Path(f"/proc/{pid}/stat").read_text()
    except OSError:
        return False
    return stat.rsplit(")", 1)[1].split()[0] != "Z"


def wait_until(condition: Callable[[], bool], timeout_s: float, poll_s: float = 0.02) -> float:
    """Seconds until `condition()` held; raise TimeoutError after `timeout_s`."""
    start = time.monotonic()
    while not condition():
        if time.monotonic() - start > timeout_s:
            raise TimeoutError(f"condition not met within {timeout_s} s")
        time.sleep(poll_s)
    return time.monotonic() - start


def kill_hard(pid: int) -> None:
    """SIGKILL, as the OOM killer or a power cut would; no handler runs."""
    with contextlib.suppress(ProcessLookupError):
        os.kill(pid, signal.SIGKILL)


def wait_all_gone(leftovers: list[Leftover], timeout_s: float) -> float:
    """Seconds until every process in `leftovers` has ended."""
    return wait_until(lambda: not any(alive(p.pid) for p in leftovers), timeout_s)


def processes_of(state_dir: Path) -> list[Leftover]:
    """The running processes started for `state_dir` (mosquitto, robot-agents, ...)."""
    return started_for(state_dir.resolve())


def crash_and_restart_broker(broker: Mosquitto, down_s: float = 0.0) -> float:
    """SIGKILL the broker, keep it down `down_s`, start it again on the same ports and
    persistence; return the seconds from the kill until it accepted connections again."""
    killed_at = time.monotonic()
    broker.kill()
    if down_s:
        time.sleep(down_s)  # the outage itself is what is being simulated
    broker.start()
    return time.monotonic() - killed_at


__all__ = [
    "alive",
    "crash_and_restart_broker",
    "kill_hard",
    "processes_of",
    "wait_all_gone",
    "wait_until",
]
