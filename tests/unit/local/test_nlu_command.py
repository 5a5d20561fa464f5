"""`vahr nlu`: the utterance profiler's JSON (a contract in docs/protocol.md, The command line), its errors, and
`vahr nlu --eval` on a labelled set."""

from __future__ import annotations

import json
from typing import TYPE_CHECKING

from vahr.cli import main

if TYPE_CHECKING:
    from pathlib import Path

    import pytest


def test_nlu_json_names_the_intent_and_every_slot(capsys: pytest.CaptureFixture[str]) -> None:
    code = main(["nlu", "Alexa, ask robot fleet to send robot nine to zone b", "--json"])
    printed = json.loads(capsys.readouterr().out)
    assert code == 0
    assert printed["intent"] == "NavigateIntent"
    # The contract's keys, then each slot's resolution as Alexa reports it.
    slots = {name: {"value": s["value"], "id": s["id"]} for name, s in printed["slots"].items()}
    assert slots == {
        "robot": {"value": "robot nine", "id": None},
        "zone": {"value": "zone b", "id": "B"},
    }
    assert printed["slots"]["robot"]["resolution"] == "ER_SUCCESS_NO_MATCH"
    assert printed["slots"]["zone"]["resolution"] == "ER_SUCCESS_MATCH"
    assert printed["slots"]["zone"]["name"] == "zone b"
    assert 0.5 <= printed["confidence"] <= 1.0
    assert printed["sample"] == "send {robot} to {zone}"


def test_nlu_json_reports_a_misheard_name_and_how_close_it_was(
    capsys: pytest.CaptureFixture[str],
) -> None:
    assert main(["nlu", "please get plasebot two over to the loading dock", "--json"]) == 0
    printed = json.loads(capsys.readouterr().out)
    robot = printed["slots"]["robot"]
    assert (printed["intent"], robot["value"], robot["id"]) == (
        "NavigateIntent",
        "plasebot two",
        "placebot2",
    )
    assert 75 <= robot["similarity"] < 100


def test_nlu_json_for_the_fallback_shows_the_guess_it_set_aside(
    capsys: pytest.CaptureFixture[str],
) -> None:
    assert main(["nlu", "bake me a cake", "--json"]) == 0
    printed = json.loads(capsys.readouterr().out)
    assert printed["intent"] == "AMAZON.FallbackIntent"
    assert printed["slots"] == {}
    assert printed["sample"] is None


def test_nlu_says_when_the_simulator_would_confirm_the_reading_first(
    capsys: pytest.CaptureFixture[str],
) -> None:
    # Nothing says which zone is for sunny weather and which for rain
    utterance = "weather delivery for placebot one zone a zone c"
    assert main(["nlu", utterance, "--json"]) == 0
    printed = json.loads(capsys.readouterr().out)
    assert printed["needs_confirmation"] is True
    assert printed["roles_confidence"] < 0.5
    assert main(["nlu", utterance]) == 0
    assert "roles       unsure (confidence " in capsys.readouterr().out
    # A plain request is sure of its roles
    assert main(["nlu", "send placebot one to zone a", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["needs_confirmation"] is False


def test_an_empty_utterance_is_one_line_and_exit_2(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["nlu", "  "]) == 2
    assert capsys.readouterr().err == "vahr nlu: error: the utterance is empty\n"


def test_eval_prints_rates_per_intent(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    # Given a small labelled set with one sentence of each outcome
    labelled = tmp_path / "set.yaml"
    labelled.write_text(
        "utterances:\n"
        "  - {text: send robot one to zone b, intent: NavigateIntent,"
        " slots: {robot: placebot1, zone: B}}\n"
        "  - {text: send robot one to zone b, intent: NavigateIntent,"
        " slots: {robot: placebot2, zone: B}}\n"
        "  - {text: send robot nine to zone b, intent: NavigateIntent,"
        " slots: {robot: placebot1, zone: B}}\n"
        "out_of_domain: [bake me a cake]\n"
    )
    # When it is scored as JSON
    assert main(["nlu", "--eval", str(labelled), "--json"]) == 0
    report = json.loads(capsys.readouterr().out)
    # Then the right one, the wrong robot and the robot to ask for are each counted
    navigate = report["per_intent"]["NavigateIntent"]
    assert (navigate["n"], navigate["right"], navigate["wrong"], navigate["asks"]) == (3, 1, 1, 1)
    assert report["out_of_domain"]["fallback_rate"] == 1.0
    assert {m["outcome"] for m in report["mistakes"]} == {"wrong", "asks"}
    # And the table has a row per intent and the totals
    assert main(["nlu", "--eval", str(labelled)]) == 0
    table = capsys.readouterr().out
    assert "NavigateIntent" in table and "in domain" in table and "(out of domain)" in table


def test_eval_of_a_bad_file_is_one_line_and_exit_2(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    labelled = tmp_path / "set.yaml"
    labelled.write_text("utterances:\n  - {text: hello}\n")
    assert main(["nlu", "--eval", str(labelled)]) == 2
    [line] = capsys.readouterr().err.strip().splitlines()
    assert line.startswith("vahr nlu: error: ") and "intent" in line
    assert main(["nlu", "--eval", str(tmp_path / "missing.yaml")]) == 2
    assert "cannot read" in capsys.readouterr().err
