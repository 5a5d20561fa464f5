"""The simulated participant following the paper's procedures, and the observer's console."""

from __future__ import annotations

import io
import os
import threading
import time
from datetime import UTC, datetime
from typing import TYPE_CHECKING, Any

import pytest

from vahr.announce import AnnouncePolicy, Finished, Opened, settings_from
from vahr.announce.speech import Names
from vahr.errors import VahrError
from vahr.experiment import participant as participant_module
from vahr.experiment import timing
from vahr.experiment.eventlog import EventLog, Kind
from vahr.experiment.observer import ObserverConsole
from vahr.experiment.participant import (
    ANNOUNCE_SETTINGS,
    HEAR_TEXT,
    Console,
    SimulatedParticipant,
)
from vahr.experiment.procedures import procedure_for
from vahr.experiment.tasks import draw_plan
from vahr.protocol import decode_command

if TYPE_CHECKING:
    from pathlib import Path

    from vahr.domain import Fleet

SPEED = 100.0


class ScriptedAssistant:
    """Stands in for the Alexa simulator in these unit tests only: it answers at once."""

    def __init__(self, weather: str = "sunny") -> None:
        self.heard: list[str] = []
        self.weather = weather

    def ask(
        self,
        utterance: str,
        *,
        origin: str = "say",
        heard: dict[str, Any] | None = None,
        user: str | None = None,
    ) -> dict[str, Any]:
        self.heard.append(utterance)
        if "what is the weather" in utterance:
            speech, intent, commands = f"The weather is {self.weather}.", "WeatherIntent", []
        else:
            speech, intent = "Okay, it is on its way.", "NavigateIntent"
            commands = [f"c{len(self.heard)}"]
        return {"utterance": utterance, "speech": speech, "intent": intent, "commands": commands}


def robot_event(log: EventLog, thing: str, event: str, **data: object) -> None:
    log.append(Kind.ROBOT_EVENT, {"event": event, "thing": thing, **data})


def test_the_voice_participant_looks_for_the_robot_loaded_before_sending_it_on(
    fleet: Fleet, tmp_path: Path
) -> None:
    # Given a voice participant in task I, and robots that get loaded a moment later
    the_plan = draw_plan(fleet, 3)
    assistant = ScriptedAssistant()
    with EventLog.open(tmp_path / "log.sqlite") as log:
        log.append(Kind.TASK_STARTED, {"task": "I"}, task="I")
        participant = SimulatedParticipant(
            method="vahr",
            fleet=fleet,
            plan=the_plan,
            log=log,
            person=timing.Person(),
            seed=3,
            speed_factor=SPEED,
            assistant=assistant,
        )

        def robots() -> None:
            while len(assistant.heard) < 2:
                time.sleep(0.01)
            time.sleep(0.05)
            for thing in fleet.robot_things:
                robot_event(log, thing, "loaded", zone="LOADING")

        loader = threading.Thread(target=robots)
        loader.start()
        # When it performs the task until it has said all four orders
        participant.perform("I")
        decided = participant.wait(lambda: len(assistant.heard) == 4, timeout_s=600)
        loader.join(5)
        entries = log.entries()
    # Then it said the paper's navigation orders: both robots to LOADING, then each to its zone
    steps = procedure_for("vahr", "I", the_plan, fleet).steps
    assert decided and assistant.heard == [step.utterance for step in steps]
    # and it only sent a robot on after a glance at the screen showed it loaded
    loaded = max(e.seq for e in entries if e.data.get("event") == "loaded")
    glances = [
        e for e in entries if e.kind == Kind.INTERACTION_ENDED and e.data["channel"] == "watch"
    ]
    saw = [g for g in glances if g.data["seen"]]
    assert saw and saw[0].seq > loaded and all(g.data["counts"] is False for g in glances)
    third = next(
        e
        for e in entries
        if e.kind == Kind.INTERACTION_STARTED and e.data["text"] == steps[2].utterance
    )
    assert third.seq > saw[0].seq
    # and each exchange lasted at least its mental preparation, words and reply (wall seconds)
    ended = {e.data["id"]: e for e in entries if e.kind == Kind.INTERACTION_ENDED}
    first = next(e for e in entries if e.kind == Kind.INTERACTION_STARTED)
    model_s = (
        timing.Person().mental_s()
        + timing.Person().speaking_s(steps[0].utterance or "")
        + timing.listening_s("Okay, it is on its way.")
    )
    lasted = (ended[first.data["id"]].at - first.at).total_seconds()
    assert lasted >= model_s / SPEED * 0.95
    assert ended[first.data["id"]].data["commands"] == ["c1"]
    # and it solved puzzle parts while it waited
    assert any(e.kind == Kind.OBSERVER and e.data["what"] == "puzzle_piece" for e in entries)


class UnreachableAssistant:
    """An assistant nothing answers for: every utterance fails as `HttpAssistant` fails."""

    def __init__(self) -> None:
        self.heard: list[str] = []

    def ask(
        self,
        utterance: str,
        *,
        origin: str = "say",
        heard: dict[str, Any] | None = None,
        user: str | None = None,
    ) -> dict[str, Any]:
        self.heard.append(utterance)
        raise VahrError("nothing answers at http://127.0.0.1:1 (refused)")


def test_the_voice_participant_logs_an_exchange_the_assistant_failed_and_goes_on(
    fleet: Fleet, tmp_path: Path
) -> None:
    # Given a voice participant in task I whose assistant cannot be reached
    assistant = UnreachableAssistant()
    with EventLog.open(tmp_path / "log.sqlite") as log:
        log.append(Kind.TASK_STARTED, {"task": "I"}, task="I")
        participant = SimulatedParticipant(
            method="vahr",
            fleet=fleet,
            plan=draw_plan(fleet, 3),
            log=log,
            person=timing.Person(),
            seed=3,
            speed_factor=SPEED,
            assistant=assistant,
        )
        # When it says its first orders
        participant.perform("I")
        decided = participant.wait(lambda: len(assistant.heard) == 2, timeout_s=600)
        spoken = [
            e.data
            for e in log.entries()
            if e.kind == Kind.INTERACTION_ENDED and e.data["channel"] == "voice"
        ]
    # Then each exchange is logged with the reason, no reply and no command, and it went on
    assert decided and spoken
    assert all(
        data["error"].startswith("nothing answers at")
        and data["speech"] == ""
        and data["intent"] is None
        and data["commands"] == []
        for data in spoken
    )


def test_the_keyboard_participant_asks_the_weather_per_robot_and_clicks_navigations(
    fleet: Fleet, tmp_path: Path
) -> None:
    # Given a keyboard participant in task II, with robots already loaded
    the_plan = draw_plan(fleet, 4)
    assistant = ScriptedAssistant(weather="rainy")
    sent: list[tuple[str, bytes]] = []
    with EventLog.open(tmp_path / "log.sqlite") as log:
        log.append(Kind.TASK_STARTED, {"task": "II"}, task="II")
        participant = SimulatedParticipant(
            method="keyboard",
            fleet=fleet,
            plan=the_plan,
            log=log,
            person=timing.Person(),
            seed=4,
            speed_factor=SPEED,
            assistant=assistant,
            console=Console(lambda topic, payload: sent.append((topic, payload))),
        )
        participant.perform("II")
        for thing in fleet.robot_things:
            robot_event(log, thing, "loaded", zone="LOADING")
        decided = participant.wait(lambda: len(sent) == 4, timeout_s=600)
        entries = log.entries()
    # Then it asked the assistant twice, once per robot, and navigated by what it heard
    assert decided and assistant.heard == ["Alexa, ask robot fleet what is the weather"] * 2
    orders = [(topic.split("/")[2], decode_command(payload)) for topic, payload in sent]
    assert [(thing, c.action, c.params.zone) for thing, c in orders] == [  # type: ignore[union-attr]
        ("placebot1", "navigate", "LOADING"),
        ("placebot2", "navigate", "LOADING"),
        ("placebot1", "navigate", "C"),
        ("placebot2", "navigate", "C"),
    ]
    # and each click sequence lasted at least its KLM operators (M, H, two BB clicks)
    clicks = [
        e for e in entries if e.kind == Kind.INTERACTION_ENDED and e.data["channel"] == "click"
    ]
    assert len(clicks) == 4 and all(c.data["clicks"] == 2 for c in clicks)
    questions = [e for e in entries if e.kind == Kind.INTERACTION_ENDED and e.data.get("asks")]
    assert [q.data["asks"] for q in questions] == ["placebot1", "placebot2"]


def finished(log: EventLog, thing: str, zone: str) -> None:
    """A robot's navigation ends as it does on the wire: arrived, loaded, done."""
    at = datetime.now(UTC).isoformat()
    for event in ("arrived", "loaded", "done"):
        robot_event(log, thing, event, zone=zone, at=at, command_id=f"{thing}-{zone}",
                    action="navigate")  # fmt: skip


def announce_participant(
    fleet: Fleet, log: EventLog, sent: list[tuple[str, bytes]]
) -> SimulatedParticipant:
    """A keyboard participant who never looks and acts on the assistant's announcements."""
    return SimulatedParticipant(
        method="keyboard",
        fleet=fleet,
        plan=draw_plan(fleet, 3),
        log=log,
        person=timing.Person(monitoring="announce"),
        seed=3,
        speed_factor=SPEED,
        assistant=ScriptedAssistant(),
        console=Console(lambda topic, payload: sent.append((topic, payload))),
    )


def test_the_announce_participant_never_looks_and_acts_on_each_finished_task(
    fleet: Fleet, tmp_path: Path
) -> None:
    # Given a keyboard participant in task I who monitors by announcements
    sent: list[tuple[str, bytes]] = []
    with EventLog.open(tmp_path / "log.sqlite") as log:
        log.append(Kind.TASK_STARTED, {"task": "I"}, task="I")
        participant = announce_participant(fleet, log, sent)
        participant.perform("I")
        assert len(sent) == 2  # both robots sent to LOADING
        # When both robots are loaded and finish at the same moment
        for thing in fleet.robot_things:
            finished(log, thing, "LOADING")
        decided = participant.wait(lambda: len(sent) == 4, timeout_s=600)
        entries = log.entries()
    # Then it heard one announcement per finished task and sent each robot on after its own,
    # without a single look at the screen
    assert decided
    heard = [e for e in entries if e.kind == Kind.INTERACTION_ENDED and e.data["text"] == HEAR_TEXT]
    assert [h.data["speech"] for h in heard] == [
        "Placebot one has finished its task at the loading zone.",
        "Placebot two has finished its task at the loading zone.",
    ]
    assert [h.data["seen"] for h in heard] == [["placebot1 was loaded"], ["placebot2 was loaded"]]
    assert all(h.data["counts"] is False for h in heard)
    assert not [
        e for e in entries if e.kind == Kind.INTERACTION_ENDED and e.data["channel"] == "watch"
    ]
    clicks = [
        e for e in entries if e.kind == Kind.INTERACTION_STARTED and e.data["channel"] == "click"
    ]
    assert clicks[2].seq > heard[0].seq and clicks[3].seq > heard[1].seq


def test_the_rehearsals_settings_never_hold_back_the_finished_tasks_of_two_tasks(
    fleet: Fleet,
) -> None:
    # Given the announcer as the announce rehearsal sets it up, and the most finished tasks
    # two of the paper's tasks bring (four each) in the same minute
    now = datetime(2026, 11, 22, 10, 0, tzinfo=UTC)
    policy = AnnouncePolicy(settings_from(ANNOUNCE_SETTINGS), Names.of(fleet), lambda: now)
    signals = [Finished(thing, now, zone="A") for thing in fleet.robot_things * 4]
    # Then every one is told at once, and a stuck robot still gets through after them
    assert len(policy.observe(signals)) == 8
    stuck = Opened("placebot1", "stuck", now, reason="no progress towards B for 10 s")
    assert [a.kind for a in policy.observe([stuck])] == ["stuck"]
    assert policy.state.held == 0


def test_a_held_announcement_reaches_the_participant_without_another_robot_event(
    fleet: Fleet, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    # Given an announcer that may tell one thing a minute (study time)
    monkeypatch.setattr(participant_module, "ANNOUNCE_SETTINGS", {
        "kinds": ["done"], "max_per_window": 1, "reserve_for_urgent": 0, "window_s": 60.0,
    })  # fmt: skip
    sent: list[tuple[str, bytes]] = []
    with EventLog.open(tmp_path / "log.sqlite") as log:
        log.append(Kind.TASK_STARTED, {"task": "I"}, task="I")
        participant = announce_participant(fleet, log, sent)
        participant.perform("I")
        # When both robots finish at once and then nothing else happens
        for thing in fleet.robot_things:
            finished(log, thing, "LOADING")
        started = time.monotonic()
        decided = participant.wait(lambda: len(sent) == 4, timeout_s=600)
        waited_study_s = (time.monotonic() - started) * SPEED
    # Then the second is told once the minute is over, and the participant acts on it
    assert decided
    assert 60 <= waited_study_s < 120


def test_the_observer_marks_utterances_watching_clicks_and_puzzle_pieces(tmp_path: Path) -> None:
    sent: list[tuple[str, bytes]] = []
    with EventLog.open(tmp_path / "log.sqlite") as log:
        observer = ObserverConsole(
            log=log,
            console=Console(lambda t, p: sent.append((t, p)), "keyboard"),
            stdin=io.StringIO(),
            out=lambda line: None,
        )
        observer.perform("II")
        observer.handle("u")
        observer.handle("r")
        observer.handle("q")
        observer.handle("r")
        observer.handle("p 2")
        observer.handle("w")
        observer.handle("r")
        observer.handle("k")
        observer.handle("go placebot2 loading")
        observer.handle("send placebot1 navigate C")
        with pytest.raises(ValueError, match="not an observer command"):
            observer.handle("dance")
        entries = log.entries()
    ended = [e.data for e in entries if e.kind == Kind.INTERACTION_ENDED]
    assert [e["channel"] for e in ended] == ["voice", "voice", "watch", "click", "click"]
    # a question and watching are interaction effort, not attempts to command the robots
    assert ended[1]["counts"] is False and ended[2]["counts"] is False
    assert "counts" not in ended[0]
    assert [e.data["count"] for e in entries if e.kind == Kind.OBSERVER] == [2]
    first, second = (decode_command(payload) for _, payload in sent)
    assert [t for t, _ in sent] == ["vahr/robots/placebot2/cmd", "vahr/robots/placebot1/cmd"]
    assert (first.action, first.params.zone, first.source) == ("navigate", "LOADING", "console")  # type: ignore[union-attr]
    assert ended[3]["commands"] == [first.id] and second.params.zone == "C"  # type: ignore[union-attr]


def test_the_observer_ends_a_task_on_e(tmp_path: Path) -> None:
    # Given the observer's keyboard as a real pipe holding "p" then "e"
    read_end, write_end = os.pipe()
    os.write(write_end, b"p\ne\n")
    os.close(write_end)
    with EventLog.open(tmp_path / "log.sqlite") as log, os.fdopen(read_end) as keyboard:
        observer = ObserverConsole(
            log=log, console=Console(lambda t, p: None), stdin=keyboard, out=lambda line: None
        )
        observer.perform("II")
        # When the task is waited for, Then "e" ends it undecided after one puzzle piece
        assert observer.wait(lambda: False, timeout_s=5) is False
        assert [e.kind for e in log.entries()] == [Kind.OBSERVER]
