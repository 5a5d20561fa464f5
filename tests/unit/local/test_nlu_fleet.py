"""`vahr nlu --fleet FILE`: utterances understood with another fleet's names, its interaction
model generated in memory, and a broken file refused in one line."""

from __future__ import annotations

import json
from typing import TYPE_CHECKING

from tests.support.fleets import SIX_ROBOTS, bad_fleet
from vahr.cli import main

if TYPE_CHECKING:
    import pytest


def test_nlu_knows_the_names_of_the_fleet_it_is_given(capsys: pytest.CaptureFixture[str]) -> None:
    # When an utterance names a robot and a zone of the six-robot fleet
    code = main(["nlu", "--fleet", str(SIX_ROBOTS), "send the plover to the oven room", "--json"])
    # Then both resolve to that fleet's ids
    printed = json.loads(capsys.readouterr().out)
    assert code == 0 and printed["intent"] == "NavigateIntent"
    slots = {name: (slot["value"], slot["id"]) for name, slot in printed["slots"].items()}
    assert slots == {"robot": ("the plover", "plover"), "zone": ("the oven room", "OVEN")}


def test_nlu_refuses_a_broken_fleet_file_in_one_line(capsys: pytest.CaptureFixture[str]) -> None:
    path = bad_fleet("duplicate_zone")
    assert main(["nlu", "--fleet", str(path), "send rover one to the north bay"]) == 2
    assert capsys.readouterr().err == (
        f"vahr nlu: error: {path}: zones.2.id: 'NORTH' is used twice (also zones.1.id)\n"
    )
