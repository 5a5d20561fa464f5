"""Regressions for the bugs the fuzz tests found (tests/fuzz/), one test per bug, each in
the words a user would see."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from vahr.cli import main as vahr_main
from vahr.domain import Fleet
from vahr.errors import VahrError
from vahr.experiment.results import read_csv
from vahr.protocol import ProtocolError, decode_command
from vahr.twin.shadow_store import ShadowError, ShadowStore

ROOT = Path(__file__).resolve().parents[2]


def _command(**fields: object) -> bytes:
    body = {
        "id": "c1", "action": "navigate", "params": {"zone": "A"},
        "issued_at": "2026-11-22T10:00:00Z", "source": "console",
    }  # fmt: skip
    body.update(fields)
    return json.dumps(body).encode()


def test_a_rejection_quoting_an_action_with_a_line_break_stays_on_one_line() -> None:
    with pytest.raises(ProtocolError) as rejected:
        decode_command(_command(action="\n"))
    assert str(rejected.value).startswith("action: '\\n' is not a known action; actions are ")


def test_a_rejection_quoting_a_long_action_is_short() -> None:
    with pytest.raises(ProtocolError) as rejected:
        decode_command(_command(action="x" * 5000))
    assert str(rejected.value).startswith(f"action: '{'x' * 39}…' is not a known action;")
    assert len(str(rejected.value)) < 200


def test_a_rejection_naming_an_unknown_field_the_sender_made_up_is_short() -> None:
    with pytest.raises(ProtocolError) as rejected:
        decode_command(_command(params={"zone": "A", "k" * 5000: 1}))
    assert str(rejected.value) == f"params.{'k' * 39}…: is not a known field"


def test_a_fleet_with_a_bad_experiment_thing_is_refused_naming_the_field() -> None:
    text = (
        (ROOT / "fleet.yaml")
        .read_text()
        .replace("experiment_thing: vahr-experiment", "experiment_thing: ''")
    )
    with pytest.raises(ProtocolError) as refused:
        Fleet.from_yaml(text)
    assert refused.value.field == "experiment_thing"
    assert "is not a valid thing name" in refused.value.reason


def test_a_results_file_that_is_not_utf8_is_refused_in_one_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    results = tmp_path / "results.csv"
    results.write_bytes(b"participant,method\n\xff\xfe,voice\n")
    with pytest.raises(VahrError) as refused:
        read_csv(results)
    assert str(refused.value) == f"{results} is not UTF-8 text (byte 19 cannot be read)"
    # And `vahr report` says so in one line with exit code 2
    assert vahr_main(["report", str(results), "--out", str(tmp_path / "out")]) == 2
    assert capsys.readouterr().err.strip().splitlines() == [
        f"vahr report: error: {results} is not UTF-8 text (byte 19 cannot be read)"
    ]


def test_a_shadow_update_nested_deeper_than_the_parser_goes_is_a_400() -> None:
    store = ShadowStore(None)
    for depth, message in (
        (900, "JSON nests arrays too deeply; maximum is 32 levels"),
        (4000, "JSON contains too many levels of nesting; maximum is 6"),
    ):
        payload = b'{"state":{"reported":{"a":' + b"[" * depth + b"]" * depth + b"}}}"
        with pytest.raises(ShadowError) as rejected:
            store.update("placebot1", None, payload)
        assert (rejected.value.code, rejected.value.message) == (400, message)


def test_a_room_message_nested_deeper_than_the_parser_goes_is_not_speech() -> None:
    from vahr.speech.errors import SpeechError
    from vahr.speech.room_channel import Utterance

    with pytest.raises(SpeechError, match="^room message is not an utterance: "):
        Utterance.decode(b"[" * 4000 + b"]" * 4000)


def test_a_results_row_without_interaction_is_refused_in_one_line(tmp_path: Path) -> None:
    # fan-out = task time / RAD, and RAD = 0 without any interaction (found by tests/fuzz/)
    results = tmp_path / "results.csv"
    header = "participant,method,trial,interaction_time_s,neglect_time_s,task_time_s,puzzle_parts,mental,physical,temporal,performance,effort,frustration,confidence,trust"
    results.write_text(f"{header}\nP0,console,1,0,40,60,3,10,3,8,15,9,4,17,16\n")
    with pytest.raises(VahrError) as refused:
        read_csv(results)
    assert str(refused.value) == (
        "row 2: interaction_time_s is 0; fan-out (task time / RAD) is undefined"
    )
