"""`robot-agent speak` and `robot-agent hear`: the voice path alone, as a user runs it."""

from __future__ import annotations

import json
from typing import TYPE_CHECKING

from robot_agent.cli import main
from vahr.speech.audio import Audio

if TYPE_CHECKING:
    from pathlib import Path

    import pytest


def test_speak_then_hear_round_trips_an_answer(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # Given the robot's voice renders the skill's answer to a file
    wav = tmp_path / "answer.wav"
    assert main(["speak", "The weather is sunny.", "--out", str(wav), "--voice", "en-us+m3"]) == 0
    assert capsys.readouterr().out.strip() == str(wav)
    assert Audio.from_wav(wav.read_bytes()).seconds > 0.5
    # When the robot hears that file
    assert main(["hear", str(wav), "--json"]) == 0
    # Then it prints the text, the intent and a confidence
    heard = json.loads(capsys.readouterr().out)
    assert heard["text"] == "the weather is sunny"
    assert heard["intent"] == "sunny"
    assert 0.5 <= heard["confidence"] <= 1.0


def test_hear_a_silent_file_is_unknown(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    wav = tmp_path / "silence.wav"
    wav.write_bytes(Audio.silence(1.5).to_wav())
    assert main(["hear", str(wav), "--json"]) == 0
    assert json.loads(capsys.readouterr().out) == {
        "text": "",
        "intent": "unknown",
        "confidence": 0.0,
    }


def test_hear_a_missing_file_is_one_line_and_exit_2(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(["hear", str(tmp_path / "none.wav")]) == 2
    err = capsys.readouterr().err
    assert (
        err.strip()
        == f"robot-agent hear: error: {tmp_path / 'none.wav'}: No such file or directory"
    )


def test_hear_a_file_that_is_not_audio_is_one_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    bad = tmp_path / "notes.wav"
    bad.write_text("shopping list")
    assert main(["hear", str(bad)]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith(f"robot-agent hear: error: {bad}: not readable audio")
    assert "\n" not in err


def test_speak_with_an_unknown_voice_says_so(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "x.wav"
    assert main(["speak", "hello", "--out", str(out), "--voice", "zz"]) == 2
    assert "espeak-ng voice 'zz'" in capsys.readouterr().err
    assert not out.exists()
