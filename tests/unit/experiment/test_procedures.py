"""The paper's procedures: what each method may send, what must be seen first, and the judge."""

from __future__ import annotations

import io
import json
import re
from pathlib import Path
from typing import TYPE_CHECKING

import pytest

from tests.unit.experiment.conftest import SessionScript, plan
from vahr.experiment.eventlog import EventLog, Kind
from vahr.experiment.judge import judge_session
from vahr.experiment.observer import ObserverConsole
from vahr.experiment.participant import Console
from vahr.experiment.procedures import (
    PROCEDURE,
    WEATHER,
    Observation,
    ProcedureViolation,
    allowed_actions,
    procedure_for,
)
from vahr.experiment.tasks import TASKS, draw_plan
from vahr.protocol import decode_command

if TYPE_CHECKING:
    from vahr.domain import Fleet

MODEL = Path(__file__).resolve().parents[3] / "skill-package/interactionModels/custom/en-US.json"
COMPOUND = ("deliver", "weather_delivery", "sequential_delivery")


@pytest.mark.parametrize("seed", [1, 2, 3, 4])
def test_keyboard_procedures_only_navigate(fleet: Fleet, seed: int) -> None:
    # Given any session's plan
    the_plan = draw_plan(fleet, seed)
    for task in TASKS:
        # When the keyboard-and-mouse procedure of each task is built
        procedure = procedure_for("keyboard", task, the_plan, fleet)
        # Then every order it gives is a navigation (a question to the assistant sends none)
        assert allowed_actions("keyboard", task) == {"navigate"}
        assert {s.action for s in procedure.steps if not s.is_question} == {"navigate"}


@pytest.mark.parametrize("action", COMPOUND)
def test_the_keyboard_console_cannot_send_a_compound_command(action: str) -> None:
    # Given the keyboard-and-mouse panel's send path
    sent: list[tuple[str, bytes]] = []
    console = Console(lambda topic, payload: sent.append((topic, payload)), "keyboard")
    # When a compound command is sent in any task, Then it is refused and nothing goes out
    for task in TASKS:
        with pytest.raises(ProcedureViolation, match=f"uses navigate, not {action}"):
            console.send("placebot1", action, {"zone": "D"}, task=task)
    assert sent == []
    # while a navigation order goes out as the skill would send it
    console.send("placebot1", "navigate", {"zone": "LOADING"}, task="I")
    (command,) = (decode_command(payload) for _, payload in sent)
    assert (command.action, command.source) == ("navigate", "console")


def test_the_observer_console_offers_no_compound_command_in_a_keyboard_session(
    tmp_path: Path,
) -> None:
    sent: list[tuple[str, bytes]] = []
    with EventLog.open(tmp_path / "log.sqlite") as log:
        observer = ObserverConsole(
            log=log,
            console=Console(lambda t, p: sent.append((t, p)), "keyboard"),
            stdin=io.StringIO(),
            out=lambda line: None,
        )
        observer.perform("III")
        # When the observer tries the compound commands, Then each is refused by name
        for line in ("send placebot1 deliver D", "send placebot2 sequential_delivery D placebot1"):
            with pytest.raises(ProcedureViolation, match="uses navigate"):
                observer.handle(line)
        # and the participant's clicked order goes out as a navigation
        observer.handle("go placebot1 loading")
        ended = [e.data for e in log.entries(Kind.INTERACTION_ENDED)]
    assert [decode_command(p).action for _, p in sent] == ["navigate"]
    assert len(ended) == 1 and ended[0]["channel"] == "click"


def test_a_voice_session_sends_nothing_from_the_observer_console(tmp_path: Path) -> None:
    with EventLog.open(tmp_path / "log.sqlite") as log:
        observer = ObserverConsole(
            log=log, console=Console(lambda t, p: None, "vahr"), stdin=io.StringIO(), out=print
        )
        observer.perform("I")
        with pytest.raises(ProcedureViolation, match="gives its orders by voice"):
            observer.handle("go placebot1 LOADING")


def test_what_must_be_observed_before_each_step(fleet: Fleet) -> None:
    the_plan = draw_plan(fleet, 3)
    third = procedure_for("keyboard", "III", the_plan, fleet)
    # placebot1 goes to LOADING at once, on to D once loaded; placebot2 only after
    # placebot1 delivered
    assert [(s.thing, s.zone) for s in third.steps] == [
        ("placebot1", "LOADING"),
        ("placebot1", "D"),
        ("placebot2", "LOADING"),
        ("placebot2", "D"),
    ]
    assert third.must_observe_before(0) == ()
    assert third.must_observe_before(1) == (Observation("placebot1", "loaded"),)
    assert Observation("placebot1", "delivered") in third.must_observe_before(2)
    ready = third.ready({Observation("placebot1", "loaded")}, done={0})
    assert [s.index for s in ready] == [1]
    # Task II with keyboard and mouse: the weather is asked once per robot, and the zone is
    # the one the answer calls for
    second = procedure_for("keyboard", "II", the_plan, fleet)
    questions = [s for s in second.steps if s.is_question]
    assert [s.thing for s in questions] == ["placebot1", "placebot2"]
    last = second.steps[-1]
    assert last.zone == WEATHER and Observation(last.thing, "answered") in last.requires
    assert last.resolved("rainy").zone == "C"


def _samples() -> list[tuple[str, re.Pattern[str]]]:
    model = json.loads(MODEL.read_text())["interactionModel"]["languageModel"]
    return [
        (intent["name"], re.compile("^" + re.sub(r"\\\{\w+\\\}", "(.+)", re.escape(s)) + "$"))
        for intent in model["intents"]
        for s in intent.get("samples", [])
    ]


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_every_utterance_is_a_sample_of_the_intent_the_paper_names(fleet: Fleet, seed: int) -> None:
    the_plan, samples = draw_plan(fleet, seed), _samples()
    expected = {
        ("vahr", "I"): "NavigateIntent",
        ("vahr", "II"): "WeatherDeliveryIntent",
        ("vahr", "III"): "SequentialDeliveryIntent",
        ("keyboard", "II"): "WeatherIntent",
    }
    for (method, task), intent in expected.items():
        for step in procedure_for(method, task, the_plan, fleet).steps:
            if step.utterance is None:
                continue
            said = re.sub(
                r"^alexa ask robot fleet (to )?", "", step.utterance.lower().replace(",", "")
            )
            assert intent in {name for name, pattern in samples if pattern.match(said)}, said


def _keyboard_task_three(script: SessionScript, second_sent_at: float) -> None:
    """placebot1 loads and delivers to D at t=40; placebot2 is sent at `second_sent_at`."""
    the_plan = plan()
    script.log.append(
        Kind.SESSION_STARTED,
        {
            "participant": "P01",
            "method": "keyboard",
            "trial": 1,
            "plan": the_plan.to_json(),
            "robots": ["placebot1", "placebot2"],
            "procedure": PROCEDURE,
        },
    )
    script.start("III", 0)
    later = max(second_sent_at, 40)
    story = [
        (1, lambda: script.command(1, "c1", "navigate", zone="LOADING", target="placebot1")),
        (10, lambda: script.robot(10, "placebot1", "loaded", "LOADING", "c1")),
        (12, lambda: script.command(12, "c2", "navigate", zone="D", target="placebot1")),
        (
            second_sent_at,
            lambda: script.command(
                second_sent_at, "c3", "navigate", zone="LOADING", target="placebot2"
            ),
        ),
        (40, lambda: script.robot(40, "placebot1", "delivered", "D", "c2")),
        (later + 10, lambda: script.robot(later + 10, "placebot2", "loaded", "LOADING", "c3")),
        (
            later + 12,
            lambda: script.command(later + 12, "c4", "navigate", zone="D", target="placebot2"),
        ),
        (later + 50, lambda: script.robot(later + 50, "placebot2", "delivered", "D", "c4")),
    ]
    for _, happen in sorted(story, key=lambda item: item[0]):  # logged in the order it happened
        happen()
    script.end(later + 51)


def test_keyboard_task_three_fails_when_placebot2_is_sent_before_placebot1_delivered(
    script: SessionScript,
) -> None:
    # Given a keyboard session where placebot2 was sent off before placebot1 had delivered,
    # although the deliveries still came in the right order
    _keyboard_task_three(script, second_sent_at=20)
    # When the judge scores it, Then task III failed for breaking the procedure
    outcome = judge_session(script.log.entries(), plan()).tasks["III"]
    assert outcome.success is False
    assert outcome.reason == "placebot2 was sent to LOADING before placebot1 delivered"


def test_keyboard_task_three_succeeds_when_placebot2_waits_for_placebot1(
    script: SessionScript,
) -> None:
    _keyboard_task_three(script, second_sent_at=45)
    outcome = judge_session(script.log.entries(), plan()).tasks["III"]
    assert outcome.success is True, outcome.reason


def test_a_compound_command_fails_the_task_where_the_paper_did_not_use_it(
    script: SessionScript,
) -> None:
    # Given a voice session whose task I was done with the compound "deliver" intent
    the_plan = plan()
    script.log.append(
        Kind.SESSION_STARTED,
        {"method": "vahr", "plan": the_plan.to_json(), "procedure": PROCEDURE},
    )
    script.start("I", 0)
    for thing, zone, ident in (("placebot1", "B", "d1"), ("placebot2", "D", "d2")):
        script.command(1, ident, "deliver", zone=zone, target=thing)
        script.robot(30, thing, "delivered", zone, ident)
    script.end(31)
    # Then the task fails and says which intent the paper's procedure uses instead
    outcome = judge_session(script.log.entries(), the_plan).tasks["I"]
    assert outcome.success is False
    assert "deliver was sent, but the vahr procedure of task I uses navigate" in outcome.reason
