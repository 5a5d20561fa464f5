"""The dialog through push-to-talk (`POST /api/voice` on a running `vahr up`), spoken by flite
voices built from recordings of people: a whole command answering "which robot?" is acted
on with its own zone, never the old one; "no, zone a" turns the robot the last command sent,
"cancel that" stops only it, and "not that robot" offers the other, which a spoken yes
sends; an answer to "Zone B or zone D?" is weighed as an answer, and asked again it offers
"bravo or delta", which the hearing tells apart, and an answer not caught gets the question
again; a chord of music, and then a correction with nothing to correct, move nothing and say
so. Each test has a stack of its own (a correction reaches back to the speaker's last
command); within one, each case begins with a command of its own. The same cases typed are
in tests/integration/local/test_dialog_corrections.py."""

from __future__ import annotations

import json
import time
import urllib.request
from typing import TYPE_CHECKING, Any

import numpy as np
import pytest

from tests.support.push_to_talk import clip, type_in
from tests.support.push_to_talk import talk as talk_to
from tests.support.vahr_up import Up, start_up, stop_up
from vahr.plumbing.ports import free_port
from vahr.speech.audio import Audio

if TYPE_CHECKING:
    from collections.abc import Iterator

WAIT_S = 30.0


@pytest.fixture
def up(tmp_path: Any) -> Iterator[Up]:
    # A stack of its own for each test: a correction reaches back to the last command of
    # the same speaker, which must be this test's (within a test, each case sends its own).
    running = start_up(tmp_path, "--station-port", str(free_port()), "--sim-speed-factor", "4")
    try:
        yield running
    finally:
        stop_up(running.process)


def talk(up: Up, voice: str, text: str) -> dict[str, Any]:
    return talk_to(up.endpoints["station"], clip(voice, text))


def robots(up: Up) -> dict[str, dict[str, Any]]:
    with urllib.request.urlopen(up.endpoints["api"] + "/vahr/status", timeout=10) as answer:
        found: dict[str, dict[str, Any]] = json.loads(answer.read())["robots"]
        return found


def eventually(up: Up, thing: str, **wanted: Any) -> dict[str, Any]:
    deadline = time.monotonic() + WAIT_S
    while True:
        state = robots(up)[thing]
        if all(state.get(key) == value for key, value in wanted.items()):
            return state
        if time.monotonic() > deadline:
            pytest.fail(f"{thing} is {state}, not {wanted}, after {WAIT_S:g} s")
        time.sleep(0.2)


def music() -> Audio:
    """Three seconds of a chord on a beat: nothing a recognizer of commands can catch."""
    seconds = np.arange(3 * 16_000) / 16_000
    chord = sum(np.sin(2 * np.pi * f * seconds) for f in (261.6, 329.6, 392.0, 523.3))
    beat = (np.sin(2 * np.pi * 2 * seconds) > 0) * 0.5 + 0.5
    return Audio.from_samples(chord * beat * 4000)


def heading(state: dict[str, Any]) -> str | None:
    """Where a robot is going, or, arrived, where it is."""
    return state.get("destination") or state.get("zone")


def answer_turns_placebot_one(up: Up, voice: str, answer: str, zone: str) -> None:
    """`answer` to "Zone B or zone D?" turns placebot one from zone C to `zone`."""
    done = talk(up, voice, answer)
    turned = f"Okay, not zone C. Placebot one is on its way to zone {zone}."
    assert done["speech"].startswith(turned), done
    eventually(up, "placebot1", destination=zone)


def send_placebot_one_to_c(up: Up, voice: str) -> None:
    """The command the corrections below correct, spoken and acted on."""
    sent = talk(up, voice, "send placebot one to zone c")
    assert sent["speech"].startswith("Placebot one is on its way to zone C."), sent


def test_a_whole_command_answering_which_robot_is_acted_on_with_its_own_zone(up: Up) -> None:
    # Given the station asked which robot should drive to zone D
    asked = talk(up, "flite:rms", "drive over to zone d")
    assert asked["speech"].startswith("Which robot"), asked
    # When the answer is a whole command naming another zone
    answer = talk(up, "flite:rms", "robot two please go to zone a")
    # Then it is acted on with its own zone, not the old one: both recognizers heard it
    # alike, read as the answer to the question
    assert answer["heard"]["weighed"]["agreed"] is True, answer
    assert answer["speech"].startswith("Placebot two is on its way to zone A."), answer
    eventually(up, "placebot2", zone="A", status="idle")
    assert robots(up)["placebot1"].get("last_command") is None


def test_no_zone_a_turns_the_robot_cancel_that_stops_only_it_and_not_that_robot_asks(
    up: Up,
) -> None:
    send_placebot_one_to_c(up, "flite:rms")
    corrected = talk(up, "flite:rms", "no, zone a")
    assert corrected["speech"].startswith(
        "Okay, not zone C. Placebot one is on its way to zone A."
    ), corrected
    eventually(up, "placebot1", destination="A")
    undone = talk(up, "flite:rms", "cancel that")
    assert undone["speech"].startswith("Okay, I cancelled that. Placebot one has stopped."), undone
    eventually(up, "placebot1", status="stopped")
    # Placebot two, never named, was never sent anywhere
    assert robots(up)["placebot2"].get("last_command") is None

    # A new command, then "not that robot": the other robot is offered, and a spoken yes to
    # the skill's yes-or-no question is weighed as the answer (alone it is no request at all)
    send_placebot_one_to_c(up, "flite:rms")
    asked = talk(up, "flite:rms", "not that robot")
    assert asked["speech"] == "Placebot two instead?", asked
    confirmed = talk(up, "flite:rms", "yes")
    assert "Placebot two is on its way to zone C" in confirmed["speech"], confirmed
    eventually(up, "placebot1", status="stopped")
    eventually(up, "placebot2", destination="C")


def test_an_answer_to_zone_b_or_zone_d_is_weighed_and_one_not_caught_is_asked_again(
    up: Up,
) -> None:
    send_placebot_one_to_c(up, "flite:awb")
    # "no, zone b": B and D are the letters the hearing confuses, so it asks
    asked = talk(up, "flite:awb", "no, zone b")
    assert asked["speech"] == "Zone B or zone D?", asked
    # The answer is weighed as an answer to that question (not as a request of its own,
    # which "zone b" alone is not): still unsure between the two, it asks again, now
    # offering the spelling-alphabet words
    again = talk(up, "flite:awb", "zone b")
    assert again["speech"] == "Zone B or zone D? You can also say bravo or delta.", again
    assert again["heard"]["weighed"]["intent"] == "CorrectionIntent"
    assert heading(robots(up)["placebot1"]) == "C"
    # which the hearing tells apart
    answer_turns_placebot_one(up, "flite:awb", "bravo", "B")

    # The question again, typed into being (the station's typing and its voice share the
    # conversation)
    assert type_in(up.endpoints["station"], "send placebot one to zone c")["commands"]
    asked = type_in(up.endpoints["station"], "no, zone b or zone d")
    assert asked["speech"] == "Zone B or zone D?", asked
    # A clip heard as nothing: the question is still open, so it is asked again, with how
    # else to answer it (as an Echo speaks the skill's reprompt)
    answer = talk_to(up.endpoints["station"], music())
    assert answer["speech"] == (
        "Sorry, I didn't catch that. I sent nothing to the robots. "
        "Zone B or zone D? You can also say bravo or delta."
    ), answer
    assert heading(robots(up)["placebot1"]) == "C"
    answer_turns_placebot_one(up, "flite:rms", "delta", "D")


def test_music_moves_nothing_and_a_correction_with_nothing_to_correct_says_so(up: Up) -> None:
    # Music is not taken for a command
    answer = talk_to(up.endpoints["station"], music())
    assert answer["understood"] is False
    assert "sent nothing to the robots" in answer["speech"]
    assert all(state.get("last_command") is None for state in robots(up).values())
    # so a correction after it has nothing to correct
    answer = talk(up, "flite:awb", "i meant placebot two")
    assert answer["speech"] == "There is no command of mine to correct, so I changed nothing."
    assert answer["turn"]["commands"] == []
    assert all(state.get("last_command") is None for state in robots(up).values())
