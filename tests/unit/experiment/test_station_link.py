"""The session's side of the operator station: the participant's input logged on this
machine's clock, and the status (briefing, live verdicts) the station shows."""

from __future__ import annotations

import json
from datetime import UTC, datetime, timedelta
from typing import TYPE_CHECKING, Any

import pytest

from tests.unit.experiment.conftest import SessionScript, plan
from vahr.experiment.eventlog import EventLog, Kind
from vahr.experiment.measure import measure_session
from vahr.experiment.recorder import Recorder
from vahr.experiment.session import OpenSession, SessionSpec
from vahr.experiment.station_link import session_status, task_statuses
from vahr.experiment.world import World
from vahr.protocol import topics

if TYPE_CHECKING:
    from collections.abc import Iterator
    from pathlib import Path

    from vahr.domain import Fleet

SESSION = "P01-keyboard-trial1"


@pytest.fixture
def log(tmp_path: Path) -> Iterator[EventLog]:
    with EventLog.open(tmp_path / f"{SESSION}.sqlite") as opened:
        yield opened


def station_input(**fields: Any) -> bytes:
    return json.dumps({"kind": "interaction", "session": SESSION, **fields}).encode()


def stamp(at: datetime) -> str:
    return at.isoformat()


def test_the_participants_clicks_are_logged_as_interactions_on_this_clock(
    log: EventLog, fleet: Fleet
) -> None:
    recorder = Recorder(log, World.from_fleet(fleet), session=SESSION)
    recorder.set_task("I")
    # Given a tablet whose clock is ten minutes slow, and a click lasting 400 ms whose end
    # is sent 50 ms after the release
    slow = datetime.now(UTC) - timedelta(minutes=10)
    before = datetime.now(UTC)
    recorder.on_message(
        topics.EXPERIMENT_INPUT,
        station_input(id="a-1", phase="started", channel="click", text="click zone B",
                      at=stamp(slow), sent=stamp(slow)),
    )  # fmt: skip
    recorder.on_message(
        topics.EXPERIMENT_INPUT,
        station_input(id="a-1", phase="ended", channel="click", text="click zone B",
                      at=stamp(slow + timedelta(milliseconds=400)),
                      sent=stamp(slow + timedelta(milliseconds=450)), commands=["c9"]),
    )  # fmt: skip
    started, ended = log.entries(Kind.INTERACTION_STARTED), log.entries(Kind.INTERACTION_ENDED)
    # Then both are logged in the task, on this machine's clock, with the command
    assert [e.data["id"] for e in started + ended] == ["station-a-1", "station-a-1"]
    assert started[0].task == ended[0].task == "I"
    assert started[0].at >= before - timedelta(seconds=1)
    assert ended[0].data["commands"] == ["c9"] and "counts" not in ended[0].data
    # And the click's time is interaction effort as the judge measures it
    assert (ended[0].at - started[0].at) >= timedelta(milliseconds=300)


def test_a_selecting_click_and_a_question_are_told_apart(log: EventLog, fleet: Fleet) -> None:
    recorder = Recorder(log, World.from_fleet(fleet), session=SESSION)
    now = stamp(datetime.now(UTC))
    for ident, extra in (("s", {"counts": False}), ("q", {"asks": True, "speech": "It is sunny."})):
        recorder.on_message(
            topics.EXPERIMENT_INPUT,
            station_input(id=ident, phase="ended", channel="click", at=now, sent=now, **extra),
        )
    select, question = (e.data for e in log.entries(Kind.INTERACTION_ENDED))
    assert select["counts"] is False
    assert question["asks"] is True and question["speech"] == "It is sunny."


def test_input_for_another_session_or_malformed_is_not_logged(log: EventLog, fleet: Fleet) -> None:
    recorder = Recorder(log, World.from_fleet(fleet), session=SESSION)
    now = stamp(datetime.now(UTC))
    other = json.dumps(
        {"kind": "puzzle", "session": "P02-vahr-trial1", "count": 1, "at": now, "sent": now}
    )
    recorder.on_message(topics.EXPERIMENT_INPUT, other.encode())
    recorder.on_message(topics.EXPERIMENT_INPUT, b'{"kind": "puzzle"}')
    recorder.on_message(topics.EXPERIMENT_INPUT, b"\xff")
    assert log.entries() == []
    # The observer's puzzle count from the station is logged like the console's
    mine = json.dumps({"kind": "puzzle", "session": SESSION, "count": 2, "at": now, "sent": now})
    recorder.on_message(topics.EXPERIMENT_INPUT, mine.encode())
    assert measure_session(log.entries()).puzzle_parts == 2


def test_nothing_is_logged_once_the_recorder_is_closed(log: EventLog, fleet: Fleet) -> None:
    recorder = Recorder(log, World.from_fleet(fleet), session=SESSION)
    recorder.close()
    now = stamp(datetime.now(UTC))
    recorder.on_message(
        topics.EXPERIMENT_INPUT,
        station_input(id="x", phase="started", channel="key", at=now, sent=now),
    )
    assert log.entries() == []


def open_session(log: EventLog, method: str = "keyboard") -> OpenSession:
    spec = SessionSpec(participant="P01", method=method, trial=1, seed=1, log_dir=log.path.parent)
    return OpenSession(spec, log, plan(), resumed=False)


def test_the_status_shows_each_tasks_verdict_as_it_stands(log: EventLog) -> None:
    script = SessionScript(log, method="keyboard")
    the_plan = plan()
    script.start_session(the_plan)
    # Task I ended well; task II running, waiting for its delivery
    script.start("I", 1)
    script.command(2, "c1", "navigate", zone="B", target="placebot1", source="console")
    script.robot(3, "placebot1", "delivered", zone="B", command_id="c1")
    script.command(4, "c2", "navigate", zone="D", target="placebot2", source="console")
    script.robot(5, "placebot2", "delivered", zone="D", command_id="c2")
    script.end(6)
    script.start("II", 7)
    statuses = task_statuses(log.entries(), open_session(log))
    assert statuses["I"].state == "success"
    assert statuses["II"].state == "running" and "waiting for placebot1" in statuses["II"].reason
    assert statuses["III"].state == "waiting"
    assert statuses["II"].title.startswith("each robot delivers according to the weather")


def test_an_order_outside_the_procedure_shows_as_failure_at_once(
    log: EventLog, fleet: Fleet
) -> None:
    # Given a session run with the paper's procedures
    script = SessionScript(log, method="keyboard")
    log.append(
        Kind.SESSION_STARTED,
        {"participant": "P01", "method": "keyboard", "trial": 1, "plan": plan().to_json(),
         "procedure": "paper", "robots": ["placebot1", "placebot2"]},
    )  # fmt: skip
    script.start("I", 1)
    # A keyboard session sends a compound command
    script.command(2, "c1", "deliver", zone="B", source="console")
    recorder = Recorder(log, World.from_fleet(fleet), session=SESSION)
    recorder.set_task("I")
    status = session_status(log.entries(), open_session(log), recorder)
    assert status.tasks["I"].state == "failure"
    assert (
        "deliver was sent, but the keyboard procedure of task I uses navigate"
        in status.tasks["I"].reason
    )
    assert status.allowed == ["navigate"] and status.task == "I"
    assert status.assignments == {"placebot1": "B", "placebot2": "D"}
