"""Corrections by push-to-talk on a running `vahr up`: after a command said at the station,
"no, zone a" turns the robot to zone A and "cancel that" stops that robot only, each said
into the talk button by festival's HTS voice (built from recordings of a person); what the
hearing is unsure of moves nothing, and the robot never named is never touched."""

from __future__ import annotations

import json
import urllib.request
from typing import TYPE_CHECKING, Any

import pytest

from tests.support.push_to_talk import clip, talk
from tests.support.vahr_up import Up, start_up, stop_up
from vahr.plumbing.ports import free_port

if TYPE_CHECKING:
    from collections.abc import Iterator

VOICE = "festival:cmu_us_slt_arctic_hts"


@pytest.fixture(scope="module")
def up(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Up]:
    # Slow enough that the robot is still driving when the correction comes.
    running = start_up(
        tmp_path_factory.mktemp("voice-corrections"),
        "--station-port", str(free_port()),
        "--sim-speed-factor", "2",
    )  # fmt: skip
    try:
        yield running
    finally:
        stop_up(running.process)


def robots(up: Up) -> dict[str, dict[str, Any]]:
    with urllib.request.urlopen(up.endpoints["api"] + "/vahr/status", timeout=10) as answer:
        found: dict[str, dict[str, Any]] = json.loads(answer.read())["robots"]
        return found


def say_at_station(up: Up, text: str) -> dict[str, Any]:
    return talk(up.endpoints["station"], clip(VOICE, text))


def test_a_correction_by_push_to_talk_redirects_or_moves_nothing(up: Up) -> None:
    sent = say_at_station(up, "send placebot one to zone c")
    assert "Placebot one is on its way to zone C" in sent["speech"], sent
    first = robots(up)["placebot1"]["last_command"]["id"]
    other_before = robots(up)["placebot2"].get("last_command")
    # A short correction is often heard too unsurely to act on (docs/push-to-talk.md):
    # then the station says so and nothing moves; when it is acted on, it is the correction.
    corrected = say_at_station(up, "no zone a")
    if corrected["understood"]:
        assert corrected["turn"]["intent"] == "CorrectionIntent", corrected
        assert "Placebot one is on its way to zone A" in corrected["speech"], corrected
        assert len(corrected["turn"]["commands"]) == 1
    else:
        assert "I sent nothing to the robots" in corrected["speech"], corrected
        assert robots(up)["placebot1"]["last_command"]["id"] == first
    undone = say_at_station(up, "cancel that")
    if undone["understood"]:
        assert undone["turn"]["intent"] == "UndoIntent", undone
        assert "Placebot one has stopped" in undone["speech"]
        [stop] = undone["turn"]["commands"]
        assert robots(up)["placebot1"]["last_command"]["id"] == stop
    else:
        assert "I sent nothing to the robots" in undone["speech"], undone
    # placebot two, never named, got nothing whatever was heard
    assert robots(up)["placebot2"].get("last_command") == other_before
