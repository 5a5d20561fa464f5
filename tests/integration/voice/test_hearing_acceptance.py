"""Acceptance of the robot's hearing (issue 13) on the whole spoken evaluation set,
`robot_agent/voice/data/hearing-eval.yaml`: 60 answers and 60 unrelated sentences in three
espeak-ng voices, clean, at 20 dB and at 10 dB SNR (1,080 clips, rendered with the set's
seed, so the same on every run; about two minutes here). `bench/hearing.py` scores the same
set and times it.

The answer targets are met; the unrelated-speech target is not yet (docs/voice.md, "How
well it hears"): that test is an expected failure until it is, and fails outright (strict)
the day it is met, so the marker is then removed."""

from __future__ import annotations

import time
from typing import TYPE_CHECKING

import pytest

from robot_agent.voice.evaluation import EVALUATION_SET, Phrasings, Report, render, score
from vahr.speech.tts import EspeakSynthesizer

if TYPE_CHECKING:
    from robot_agent.voice.understanding import Understanding

pytestmark = pytest.mark.slow


@pytest.fixture(scope="module")
def report(understanding: Understanding, tmp_path_factory: pytest.TempPathFactory) -> Report:
    # Given the evaluation set, rendered as `--make-eval-set` does
    directory = tmp_path_factory.mktemp("evaluation")
    render(Phrasings.load(EVALUATION_SET), directory, EspeakSynthesizer)
    # When the robot hears every clip
    return score(directory, understanding.hear, time.perf_counter)


def test_heard_answers_meet_the_targets(report: Report) -> None:
    # Then answers are right >= 95% clean and at 20 dB, >= 85% at 10 dB, and never taken
    # for the other weather
    rates = {c: report.answers(c).rate("right") for c in ("clean", "snr20", "snr10")}
    assert rates["clean"] >= 0.95 and rates["snr20"] >= 0.95 and rates["snr10"] >= 0.85, rates
    assert all(report.answers(c).counts["wrong"] == 0 for c in ("clean", "snr20", "snr10"))


@pytest.mark.xfail(strict=True, reason="issue 13's target for unrelated speech is not reached")
def test_unrelated_speech_is_rarely_taken_for_an_answer(report: Report) -> None:
    # Then unrelated speech is taken for an answer at most 2% of the time
    assert report.unrelated().rate("wrong") <= 0.02
