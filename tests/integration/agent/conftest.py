"""Fixtures for the agent's integration tests: a tap on the broker, a shadow responder,
a factory of real `robot-agent run` processes that are always stopped, ROS 1's master and
fake move_base (tests/support/ros1.py) and ROS 2's stand-in bt_navigator
(tests/support/nav2.py)."""

from __future__ import annotations

from typing import TYPE_CHECKING

import pytest

from tests.integration.agent.harness import AgentProcess, ShadowResponder, WireTap
from tests.support.nav2 import nav2_stand_in  # noqa: F401 - a module's stand-in
from tests.support.ros1 import move_base, ros_master  # noqa: F401 - session fixtures
from tests.unit.agent.conftest import pytest_pyfunc_call  # noqa: F401 - runs async tests

if TYPE_CHECKING:
    from collections.abc import Callable, Iterator
    from pathlib import Path

    from vahr.twin.broker import Mosquitto

FAST = "50"  # simulated time runs 50x faster than the wall clock in these tests


@pytest.fixture
def tap(mosquitto: Mosquitto) -> Iterator[WireTap]:
    wire = WireTap(mosquitto.config.plain_port or 0)
    yield wire
    wire.close()


@pytest.fixture
def shadows(mosquitto: Mosquitto) -> Iterator[ShadowResponder]:
    responder = ShadowResponder(mosquitto.config.plain_port or 0)
    yield responder
    responder.close()


@pytest.fixture
def start_agent(mosquitto: Mosquitto, tmp_path: Path) -> Iterator[Callable[..., AgentProcess]]:
    started: list[AgentProcess] = []

    def start(thing: str = "placebot1", *extra: str, state_dir: Path | None = None) -> AgentProcess:
        agent = AgentProcess(
            "--thing",
            thing,
            "--broker",
            str(mosquitto.plain_url),
            "--sim-speed-factor",
            FAST,
            *extra,
            state_dir=state_dir or tmp_path / "state",
            log_file=tmp_path / f"{thing}-{len(started)}.log",
        )
        started.append(agent)
        return agent

    yield start
    for agent in started:
        if agent.process.poll() is None:
            agent.kill()
