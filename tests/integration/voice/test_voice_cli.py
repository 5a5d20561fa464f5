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
        "evidence": [],
        "reason": "no speech",
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


def test_hear_json_says_why_it_decided(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    # Given an answer worded as no sample in weather_answers.yaml words it
    wav = tmp_path / "pouring.wav"
    assert main(["speak", "It is pouring.", "--out", str(wav), "--voice", "en-us+f4"]) == 0
    capsys.readouterr()
    # When the robot hears it
    assert main(["hear", str(wav), "--json"]) == 0
    heard = json.loads(capsys.readouterr().out)
    # Then it is rainy, and the words that decided are reported
    assert (heard["intent"], heard["reason"]) == ("rainy", "")
    assert "pouring" in heard["evidence"]
    assert "pouring" in heard["text"]


def test_hear_json_gives_the_reason_for_unknown(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    wav = tmp_path / "robot.wav"
    assert main(["speak", "Robot two is stuck.", "--out", str(wav)]) == 0
    capsys.readouterr()
    assert main(["hear", str(wav), "--json"]) == 0
    heard = json.loads(capsys.readouterr().out)
    assert (heard["text"], heard["intent"]) == ("robot two is stuck", "unknown")
    assert heard["reason"] == "robot talk (robot)"


SMALL_SET = """
voices: [en-us+f4]
snr_db: [20]
seed: 5
answers:
  sunny: [The weather is sunny.]
  rainy: [The weather is rainy.]
unrelated: [Robot two is stuck.]
"""


def test_make_eval_set_is_identical_on_every_run_and_eval_scores_it(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # Given a phrasings file rendered twice into two directories
    phrasings = tmp_path / "set.yaml"
    phrasings.write_text(SMALL_SET)
    made = []
    for name in ("one", "two"):
        assert (
            main(["hear", "--make-eval-set", str(tmp_path / name), "--phrasings", str(phrasings)])
            == 0
        )
        made.append(json.loads(capsys.readouterr().out))
    # Then both hold 3 sentences x 1 voice x (clean, 20 dB), byte for byte the same
    assert made[0]["clips"] == made[1]["clips"] == 6
    assert made[0]["sha256"] == made[1]["sha256"]
    for clip in json.loads((tmp_path / "one" / "manifest.json").read_text())["clips"]:
        assert (tmp_path / "one" / clip["file"]).read_bytes() == (
            tmp_path / "two" / clip["file"]
        ).read_bytes()
    # When the set is scored
    assert main(["hear", "--eval", str(tmp_path / "one"), "--json"]) == 0
    report = json.loads(capsys.readouterr().out)
    # Then every clip is counted per condition and intent, with the rates
    clean = report["conditions"]["clean"]
    assert clean["sunny"]["n"] == clean["rainy"]["n"] == clean["unrelated"]["n"] == 1
    assert set(report["conditions"]) == {"clean", "snr20"}
    assert report["clips"] == 6
    assert {"right_rate", "wrong_rate", "fallback_rate"} <= set(clean["answers"])
    # And the plain table has a row per condition and intent
    assert main(["hear", "--eval", str(tmp_path / "one")]) == 0
    table = capsys.readouterr().out
    assert "| clean | sunny | 1 |" in table and "| snr20 | unrelated | 1 |" in table


def test_hear_needs_exactly_one_thing_to_do(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["hear"]) == 2
    assert "give one of FILE, --eval DIR or --make-eval-set DIR" in capsys.readouterr().err


def test_eval_of_a_directory_without_a_set_is_one_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(["hear", "--eval", str(tmp_path)]) == 2
    err = capsys.readouterr().err.strip()
    assert "manifest.json" in err and "--make-eval-set" in err and "\n" not in err
