"""Push-to-talk through the station's `/api/voice` on a running `vahr up`, with clips
spoken by flite and festival (voices built from recordings of people): a clear command
acts, a command whose zone the recognizer's N best split between B and D is asked about
and moves nothing, and silence and noise move nothing."""

from __future__ import annotations

import json
import time
import urllib.request
from typing import TYPE_CHECKING, Any

import numpy as np
import pytest

from tests.support.push_to_talk import clip
from tests.support.push_to_talk import talk as talk_to
from tests.support.vahr_up import Up, start_up, stop_up
from vahr.assistant.nbest import MIN_SLOT_CONFIDENCE
from vahr.plumbing.ports import free_port
from vahr.speech.audio import Audio

if TYPE_CHECKING:
    from collections.abc import Iterator

WAIT_S = 30.0


@pytest.fixture(scope="module")
def up(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Up]:
    running = start_up(
        tmp_path_factory.mktemp("hearing-up"),
        "--station-port", str(free_port()),
        "--sim-speed-factor", "10",
    )  # fmt: skip
    try:
        yield running
    finally:
        stop_up(running.process)


def talk(up: Up, audio: Audio) -> dict[str, Any]:
    """Release of the talk button on `up`'s station: the answer's JSON."""
    return talk_to(up.endpoints["station"], audio)


def robots(up: Up) -> dict[str, dict[str, Any]]:
    with urllib.request.urlopen(up.endpoints["api"] + "/vahr/status", timeout=10) as answer:
        found: dict[str, dict[str, Any]] = json.loads(answer.read())["robots"]
        return found


def last_commands(up: Up) -> dict[str, Any]:
    return {thing: state.get("last_command") for thing, state in robots(up).items()}


def eventually_at(up: Up, thing: str, zone: str) -> None:
    deadline = time.monotonic() + WAIT_S
    while time.monotonic() < deadline:
        state = robots(up)[thing]
        if state.get("zone") == zone and state.get("status") == "idle":
            return
        time.sleep(0.2)
    pytest.fail(f"{thing} did not reach zone {zone} within {WAIT_S:g} s")


@pytest.mark.parametrize(
    ("voice", "text", "thing", "zone"),
    [
        ("flite:rms", "move placebot one to zone d", "placebot1", "D"),
        ("festival:cmu_us_slt_arctic_hts", "send placebot one to zone c", "placebot1", "C"),
    ],
)
def test_a_clear_command_acts(up: Up, voice: str, text: str, thing: str, zone: str) -> None:
    answer = talk(up, clip(voice, text))
    assert answer["understood"] is True, answer
    assert f"zone {zone}" in answer["speech"]
    assert answer["heard"]["weighed"]["slots"]["zone"] >= MIN_SLOT_CONFIDENCE
    eventually_at(up, thing, zone)


def test_a_zone_split_between_b_and_d_is_asked_about_and_nothing_moves(up: Up) -> None:
    before = last_commands(up)
    # festival's voice: the recognizer's best is "zone d", but its N best hold "zone b" too.
    answer = talk(up, clip("festival:cmu_us_slt_arctic_hts", "send placebot one to zone b"))
    weighed = answer["heard"]["weighed"]
    assert weighed["slots"]["zone"] < MIN_SLOT_CONFIDENCE, answer
    said = answer["speech"].lower()
    assert "zone b or zone d" in said or "zone d or zone b" in said
    assert answer["turn"]["commands"] == []
    time.sleep(1.0)
    assert last_commands(up) == before


@pytest.mark.parametrize(
    "audio",
    [
        Audio.silence(2.5),
        Audio.from_samples(np.random.default_rng(7).normal(0.0, 3000.0, 40_000)),
    ],
    ids=["silence", "white noise"],
)
def test_silence_and_noise_move_nothing_and_say_so(up: Up, audio: Audio) -> None:
    before = last_commands(up)
    answer = talk(up, audio)
    assert answer["understood"] is False
    assert "sent nothing to the robots" in answer["speech"]
    time.sleep(0.5)
    assert last_commands(up) == before
