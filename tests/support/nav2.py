"""ROS 2 for tests and benchmarks: the DDS isolation rules and the Nav2 stand-in's process.

Every ROS 2 graph a test makes keeps to this machine and to itself: discovery stays on
localhost (`ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST`) and each stand-in, with the backends
that talk to it, gets a ROS domain of its own (`next_domain_id`). `make pytest-ros2` runs
these tests inside a private network namespace besides, where one can be made.

`Nav2StandIn` runs `tests.support.nav2_stand_in` (a real rclpy NavigateToPose server that is
not Nav2) as a child process that dies with its parent, and steers it through its control
files.
"""

from __future__ import annotations

import contextlib
import importlib.util
import itertools
import json
import os
import random
import signal
import subprocess
import sys
import time
from pathlib import Path
from typing import TYPE_CHECKING, Any

import pytest

from vahr.plumbing.lifetime import spawn

if TYPE_CHECKING:
    from collections.abc import Iterator

ROOT = Path(__file__).resolve().parents[2]
# Whether this interpreter has ROS 2 (rclpy) and the NavigateToPose it was built with.
HAS_ROS2 = all(importlib.util.find_spec(name) for name in ("rclpy", "nav2_msgs"))
WITHOUT_ROS2 = (
    "needs ROS 2's rclpy and nav2_msgs, which live in .venv-ros2 (make setup makes it; "
    "make test runs these tests there)"
)


def _domains_of_this_process() -> list[int]:
    """Domains 1-100, shared out among pytest-xdist's workers (which share one network
    namespace), in an order of this process's own."""
    worker = os.environ.get("PYTEST_XDIST_WORKER", "gw0").removeprefix("gw")
    workers = int(os.environ.get("PYTEST_XDIST_WORKER_COUNT", "1"))
    mine = list(range(1 + int(worker) % workers, 101, workers))
    return random.sample(mine, len(mine))


_domains = itertools.cycle(_domains_of_this_process())


def next_domain_id() -> int:
    return next(_domains)


def isolate_ros2(home: Path) -> dict[str, str]:
    """Set (and return) the environment every ROS 2 process of a test run starts with."""
    settings = {
        "ROS_AUTOMATIC_DISCOVERY_RANGE": "LOCALHOST",
        "ROS_HOME": str(home),
        "ROS_LOG_DIR": str(home / "log"),
        "RCUTILS_LOGGING_BUFFERED_STREAM": "1",
    }
    os.environ.update(settings)
    return settings


class Nav2StandIn:
    """The stand-in bt_navigator in a process of its own (`python` must have ROS 2)."""

    def __init__(
        self,
        control: Path,
        *,
        domain_id: int,
        action: str = "navigate_to_pose",
        start: tuple[float, float] = (1.0, 3.0),
        python: str = sys.executable,
    ) -> None:
        self.control = control
        self.domain_id = domain_id
        self.action = action
        self.start_at = start
        self.python = python
        self.process: subprocess.Popen[Any] | None = None
        control.mkdir(parents=True, exist_ok=True)

    def start(self, timeout_s: float = 20.0) -> Nav2StandIn:
        (self.control / "ready").unlink(missing_ok=True)
        command = [
            self.python,
            "-m",
            "tests.support.nav2_stand_in",
            "--control",
            str(self.control),
            "--action",
            self.action,
            "--domain-id",
            str(self.domain_id),
            "--start",
            f"{self.start_at[0]},{self.start_at[1]}",
        ]
        with (self.control / "stand-in.log").open("ab") as output:
            self.process = spawn(
                command,
                started_for=self.control,
                death_signal=signal.SIGKILL,
                cwd=ROOT,
                stdout=output,
                stderr=subprocess.STDOUT,
            )
        deadline = time.monotonic() + timeout_s
        while not (self.control / "ready").exists():
            if self.process.poll() is not None or time.monotonic() > deadline:
                self.stop()
                raise RuntimeError(f"the Nav2 stand-in did not start:\n{self.output()}")
            time.sleep(0.02)
        return self

    def stop(self) -> None:
        """SIGTERM (rclpy leaves the graph cleanly), then SIGKILL if it lingers."""
        process, self.process = self.process, None
        if process is None or process.poll() is not None:
            return
        process.send_signal(signal.SIGTERM)
        try:
            process.wait(timeout=5)
        except subprocess.TimeoutExpired:
            process.kill()
            process.wait(timeout=5)

    def wait_exit(self, timeout_s: float = 10.0) -> int:
        assert self.process is not None
        code = self.process.wait(timeout=timeout_s)
        self.process = None
        return code

    # -- steering -----------------------------------------------------------------------

    def plan(self, *queue: dict[str, Any], default: dict[str, Any] | None = None) -> None:
        """The next goals' modes, in order (`{"mode": "abort", "error_code": ...}`), then
        `default` (succeed) for every goal after them."""
        plan = {"default": default or {"mode": "succeed"}, "queue": list(queue)}
        path = self.control / "plan.json"
        path.with_suffix(".tmp").write_text(json.dumps(plan))
        path.with_suffix(".tmp").replace(path)

    def battery(self, percentage: float, status: int) -> None:
        path = self.control / "battery.json"
        path.with_suffix(".tmp").write_text(
            json.dumps({"percentage": percentage, "status": status})
        )
        path.with_suffix(".tmp").replace(path)

    # -- what it saw --------------------------------------------------------------------

    def log(self) -> list[dict[str, Any]]:
        path = self.control / "log.jsonl"
        if not path.exists():
            return []
        return [json.loads(line) for line in path.read_text().splitlines() if line.strip()]

    def seen(self, event: str) -> list[dict[str, Any]]:
        return [entry for entry in self.log() if entry["event"] == event]

    def wait_for(self, event: str, count: int = 1, timeout_s: float = 10.0) -> dict[str, Any]:
        deadline = time.monotonic() + timeout_s
        while True:
            seen = self.seen(event)
            if len(seen) >= count:
                return seen[count - 1]
            if time.monotonic() > deadline:
                raise AssertionError(f"the stand-in saw {len(seen)} {event}: {self.log()}")
            time.sleep(0.01)

    def output(self) -> str:
        with contextlib.suppress(OSError):
            return (self.control / "stand-in.log").read_text()
        return ""


@pytest.fixture(scope="module")
def nav2_stand_in(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Nav2StandIn]:
    """One stand-in bt_navigator per test module, in a ROS domain of its own."""
    if not HAS_ROS2:
        pytest.skip(WITHOUT_ROS2)
    home = tmp_path_factory.mktemp("ros2")
    isolate_ros2(home)
    stand_in = Nav2StandIn(home / "stand-in", domain_id=next_domain_id()).start()
    yield stand_in
    stand_in.stop()
