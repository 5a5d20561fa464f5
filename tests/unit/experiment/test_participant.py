"""The simulated participant's scripts, timing model and the observer's console."""

from __future__ import annotations

import io
import json
import os
import random
import re
from pathlib import Path
from typing import TYPE_CHECKING

import pytest

from vahr.experiment.assistant import AssistantReply
from vahr.experiment.eventlog import EventLog, Kind
from vahr.experiment.observer import ObserverConsole
from vahr.experiment.participant import (
    Console,
    SimulatedParticipant,
    keyboard_script,
    voice_script,
)
from vahr.experiment.tasks import draw_plan
from vahr.experiment.timing import TimingModel
from vahr.protocol import decode_command

if TYPE_CHECKING:
    from vahr.protocol import Fleet

MODEL = Path(__file__).resolve().parents[3] / "skill-package/interactionModels/custom/en-US.json"


def sample_patterns() -> list[tuple[str, re.Pattern[str]]]:
    model = json.loads(MODEL.read_text())["interactionModel"]["languageModel"]
    patterns = []
    for intent in model["intents"]:
        for sample in intent.get("samples", []):
            regex = re.sub(r"\\\{\w+\\\}", "(.+)", re.escape(sample))
            patterns.append((intent["name"], re.compile(f"^{regex}$")))
    return patterns


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_every_utterance_is_a_sample_of_the_interaction_model(fleet: Fleet, seed: int) -> None:
    plan = draw_plan(fleet, seed)
    patterns = sample_patterns()
    expected = {
        "I": "DeliverIntent",
        "II": "WeatherDeliveryIntent",
        "III": "SequentialDeliveryIntent",
    }
    for task, intent in expected.items():
        for utterance in voice_script(task, plan, fleet):
            matched = {name for name, pattern in patterns if pattern.match(utterance)}
            assert intent in matched, utterance


def test_keyboard_scripts_send_the_commands_each_task_needs(fleet: Fleet) -> None:
    plan = draw_plan(fleet, 9)
    assert keyboard_script("I", plan) == [
        (thing, "deliver", {"zone": zone}) for thing, zone in plan.assignments.items()
    ]
    assert keyboard_script("II", plan) == [
        ("placebot1", "deliver", {"zone": "A" if plan.weather == "sunny" else "C"})
    ]
    assert keyboard_script("III", plan) == [
        ("placebot1", "deliver", {"zone": "D"}),
        ("placebot2", "sequential_delivery", {"zone": "D", "after": "placebot1"}),
    ]


def test_the_timing_model_follows_the_keystroke_level_model() -> None:
    exact = TimingModel(jitter=0.0)
    rng = random.Random(1)
    assert exact.first_click_s(rng) == pytest.approx(1.35 + 0.4 + 1.1 + 0.2)
    assert exact.next_click_s(rng) == pytest.approx(1.3)
    # "tell placebot one to do the weather delivery": 8 words at 150 per minute
    assert exact.speaking_s(rng, "tell placebot one to do the weather delivery") == pytest.approx(
        1.35 + 0.6 + 8 * 60 / 150
    )
    assert exact.listening_s(rng, "The weather is sunny.") == pytest.approx(4 * 60 / 175)
    pieces = [exact.puzzle_piece_s(random.Random(s)) for s in range(2000)]
    assert sum(pieces) / len(pieces) == pytest.approx(25, rel=0.1)


def test_the_same_seed_replays_the_same_durations() -> None:
    model = TimingModel()
    first = [model.first_click_s(random.Random(4)) for _ in range(3)]
    assert first[0] == first[1] == first[2]
    assert model.first_click_s(random.Random(5)) != first[0]


def test_the_observer_marks_utterances_clicks_and_puzzle_pieces(tmp_path: Path) -> None:
    sent: list[tuple[str, bytes]] = []
    with EventLog.open(tmp_path / "log.sqlite") as log:
        observer = ObserverConsole(
            log=log,
            console=Console(lambda t, p: sent.append((t, p))),
            stdin=io.StringIO(),
            out=lambda line: None,
        )
        observer.perform("I")
        observer.handle("u")
        log.append(Kind.COMMAND, {"id": "c-alexa", "source": "alexa", "action": "deliver"})
        observer.handle("r")
        observer.handle("p 2")
        observer.handle("k")
        observer.handle("send placebot2 deliver d")
        observer.handle("send placebot2 sequential_delivery D placebot1")
        with pytest.raises(ValueError, match="not an observer command"):
            observer.handle("dance")
        entries = log.entries()
    ended = [e.data for e in entries if e.kind == Kind.INTERACTION_ENDED]
    assert ended[0]["commands"] == ["c-alexa"] and ended[0]["channel"] == "voice"
    assert [e["channel"] for e in ended[1:]] == ["click", "click"]
    assert [e.data["count"] for e in entries if e.kind == Kind.OBSERVER] == [2]
    topics = [topic for topic, _ in sent]
    assert topics == ["vahr/robots/placebot2/cmd"] * 2
    first, second = (decode_command(payload) for _, payload in sent)
    assert (first.action, first.params.zone, first.source) == ("deliver", "D", "console")  # type: ignore[union-attr]
    assert ended[1]["commands"] == [first.id]
    assert second.params.after == "placebot1"  # type: ignore[union-attr]


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


class ScriptedAssistant:
    """Stands in for the Alexa simulator in this unit test only: it answers at once."""

    def __init__(self) -> None:
        self.heard: list[str] = []

    def ask(self, utterance: str) -> AssistantReply:
        self.heard.append(utterance)
        if "weather" in utterance:
            return AssistantReply("Sorry, I did not get that.", intent="AMAZON.FallbackIntent")
        return AssistantReply(
            "Okay, placebot one is on its way.",
            intent="DeliverIntent",
            commands=[f"c{len(self.heard)}"],
        )


def test_the_voice_participant_logs_each_exchange_as_speaking_plus_listening(
    fleet: Fleet, tmp_path: Path
) -> None:
    # Given a voice participant running 100 times faster than real time, with no jitter
    plan = draw_plan(fleet, 3)
    assistant = ScriptedAssistant()
    timing = TimingModel(jitter=0.0)
    with EventLog.open(tmp_path / "log.sqlite") as log:
        participant = SimulatedParticipant(
            method="vahr",
            fleet=fleet,
            plan=plan,
            log=log,
            timing=timing,
            seed=3,
            speed_factor=100.0,
            assistant=assistant,
        )
        # When it performs tasks I and II
        participant.perform("I")
        participant.perform("II")
        entries = log.entries()
    # Then it said the scripted sentences, in order, to the assistant
    assert assistant.heard == voice_script("I", plan, fleet) + voice_script("II", plan, fleet)
    started = [e for e in entries if e.kind == Kind.INTERACTION_STARTED]
    ended = [e for e in entries if e.kind == Kind.INTERACTION_ENDED]
    assert len(started) == len(ended) == 3
    # and each exchange lasted at least its speaking and listening time (in wall seconds)
    rng = random.Random(0)
    for start, end in zip(started, ended, strict=True):
        model_s = timing.speaking_s(rng, start.data["text"]) + timing.listening_s(
            rng, end.data["speech"]
        )
        assert (end.at - start.at).total_seconds() >= model_s / 100 * 0.95
    # and what the assistant did with each utterance is kept for the judge
    assert ended[0].data["commands"] == ["c1"] and ended[0].data["intent"] == "DeliverIntent"
    assert ended[2].data["commands"] == [] and ended[2].data["speech"].startswith("Sorry")
