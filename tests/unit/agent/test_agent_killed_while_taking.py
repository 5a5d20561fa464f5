"""A robot killed while taking a command reports it, or runs it again; it never drops it.

The robot saves a command's id among its recent ids (so a redelivery is ignored), then
reports `accepted` and saves the command as running. Killed between the two, it came back
with the id saved and no running command: nothing reported the command, and the broker's
redelivery (the link acknowledges only after handling) was ignored as a duplicate. The
command was lost without a word."""

from __future__ import annotations

import asyncio
from typing import TYPE_CHECKING

import pytest

from robot_agent.agent import RobotAgent
from robot_agent.backends.sim import SimBackend
from robot_agent.clock import ScaledClock
from robot_agent.config import SimSettings
from robot_agent.core.in_flight import InFlight
from robot_agent.core.recent_ids import RecentIds
from vahr.protocol import decode_event, encode, new_command, topics

if TYPE_CHECKING:
    from collections.abc import Callable
    from pathlib import Path

    from vahr.domain import Fleet
    from vahr.protocol import Event

THING = "placebot1"


class _Killed(BaseException):
    """SIGKILL: nothing after this point runs."""


class _KilledAfterSaving(RecentIds):
    def add(self, command_id: str) -> bool:
        super().add(command_id)
        raise _Killed


class _Link:
    def __init__(self) -> None:
        self.routes: dict[str, Callable[[str, bytes], None]] = {}
        self.events: list[Event] = []
        self.connected: list[Callable[[bool], None]] = []

    def publish(self, topic: str, payload: bytes, *, retain: bool = False) -> None:
        if topic == topics.robot_events(THING):
            self.events.append(decode_event(payload))

    def add_route(self, topic_filter: str, handler: Callable[[str, bytes], None]) -> None:
        self.routes[topic_filter] = handler

    def on_connected(self, callback: Callable[[bool], None]) -> None:
        self.connected.append(callback)

    def on_disconnected(self, callback: Callable[[str], None]) -> None:
        pass


def _robot(fleet: Fleet, state: Path, recent_ids: RecentIds) -> tuple[RobotAgent, _Link]:
    clock = ScaledClock(speed_factor=200)
    link = _Link()
    agent = RobotAgent(
        thing=THING, fleet=fleet, link=link, clock=clock, recent_ids=recent_ids,
        backend=SimBackend(start=fleet.robot(THING).start, clock=clock, settings=SimSettings()),
        in_flight=InFlight(state / "in-flight.json"),
    )  # fmt: skip
    agent.attach()
    return agent, link


def test_a_robot_killed_after_saving_a_command_id_reports_the_command(
    fleet: Fleet, tmp_path: Path
) -> None:
    command = new_command("navigate", {"zone": "B"}, source="alexa")
    cmd_topic = topics.robot_cmd(THING)

    async def scenario() -> list[Event]:
        # Given a robot killed just after it saved the id of a command it received
        agent, link = _robot(fleet, tmp_path, _KilledAfterSaving(tmp_path / "recent-ids.json"))
        for callback in link.connected:
            callback(False)
        with pytest.raises(_Killed):
            link.routes[cmd_topic](cmd_topic, encode(command))
        # When it starts again and the broker delivers the command again
        again, link = _robot(fleet, tmp_path, RecentIds(tmp_path / "recent-ids.json"))
        for callback in link.connected:
            callback(True)
        link.routes[cmd_topic](cmd_topic, encode(command))
        await asyncio.wait_for(again.executor.wait_idle(), timeout=30)
        await again.shut_down()
        return link.events

    events = asyncio.run(scenario())
    # Then the sender is told the command ended, failed with the reason, and it does not run
    about = [(e.event, e.reason or "") for e in events if e.command_id == command.id]
    assert [event for event, _ in about] == ["failed"], about
    assert about[0][1].startswith("interrupted:"), about


def test_a_robot_killed_before_saving_a_command_id_runs_its_redelivery(
    fleet: Fleet, tmp_path: Path
) -> None:
    command = new_command("navigate", {"zone": "B"}, source="alexa")
    cmd_topic = topics.robot_cmd(THING)

    async def scenario() -> list[Event]:
        # Given a robot that had noted a command as arriving but not yet saved its id
        InFlight(tmp_path / "in-flight.json").start(command.id, command.action)
        # When it starts again and the broker delivers the command again
        again, link = _robot(fleet, tmp_path, RecentIds(tmp_path / "recent-ids.json"))
        for callback in link.connected:
            callback(True)
        link.routes[cmd_topic](cmd_topic, encode(command))
        await asyncio.wait_for(again.executor.wait_idle(), timeout=30)
        await again.shut_down()
        return link.events

    events = asyncio.run(scenario())
    # Then it runs once, with nothing reported failed
    about = [e.event for e in events if e.command_id == command.id]
    assert about[0] == "accepted" and about[-1] == "done" and "failed" not in about, about
