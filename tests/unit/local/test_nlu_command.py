"""`vahr nlu`: the utterance profiler's JSON (a contract in DESIGN.md) and its errors."""

from __future__ import annotations

import json
from typing import TYPE_CHECKING

from vahr.cli import main

if TYPE_CHECKING:
    import pytest


def test_nlu_json_names_the_intent_and_every_slot(capsys: pytest.CaptureFixture[str]) -> None:
    code = main(["nlu", "Alexa, ask robot fleet to send robot nine to zone b", "--json"])
    printed = json.loads(capsys.readouterr().out)
    assert code == 0
    assert printed["intent"] == "NavigateIntent"
    assert printed["slots"] == {
        "robot": {"value": "robot nine", "id": None},
        "zone": {"value": "zone b", "id": "B"},
    }


def test_an_empty_utterance_is_one_line_and_exit_2(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["nlu", "  "]) == 2
    assert capsys.readouterr().err == "vahr nlu: error: the utterance is empty\n"
