"""Acceptance of the robot's hearing (issue 13) on the spoken evaluation set,
`robot_agent/voice/data/hearing-eval.yaml`: its 67 answers and 70 unrelated sentences, each in
one of the set's three espeak-ng voices in turn, clean and at 10 dB SNR, the set's two ends
(274 clips, rendered with the set's seed, so the same on every run: each clip's noise is
seeded by the clip, so these are the very clips the whole set holds). Hearing a clip takes
a quarter to a third of a second of CPU here, so the whole set (all three voices and 20 dB as
well: 1,233 clips, eight minutes of CPU) is scored by `bench/hearing.py`, whose figures are
in docs/benchmarks.md; this part keeps the suite within its time.

The set was written blind and scored once (docs/voice.md, "How well it hears"). What this
part measured is kept as floors, so that nothing gets worse, beside the targets, which it
meets (a target a set does not meet is held as a strict expected failure)."""

from __future__ import annotations

import time
from typing import TYPE_CHECKING

import msgspec
import pytest

from robot_agent.voice.evaluation import EVALUATION_SET, Phrasings, Report, render, score
from vahr.speech.tts import EspeakSynthesizer

if TYPE_CHECKING:
    from robot_agent.voice.hearing import Hearing

# Rendering and hearing 274 clips takes over a minute of CPU; beside the rest of the suite,
# three workers on two cores, it takes longer: the bound guards against a hang.
pytestmark = [pytest.mark.slow, pytest.mark.timeout(900)]


@pytest.fixture(scope="module")
def report(hearing: Hearing, tmp_path_factory: pytest.TempPathFactory) -> Report:
    # Given the evaluation set, rendered as `--make-eval-set` does, each sentence in one voice
    directory = tmp_path_factory.mktemp("evaluation")
    every = Phrasings.load(EVALUATION_SET)
    ends = msgspec.structs.replace(every, snr_db=[min(every.snr_db)])
    render(ends, directory, EspeakSynthesizer, voices_in_turn=True)
    # When the robot hears every clip
    return score(directory, hearing.hear, time.perf_counter)


CONDITIONS = ("clean", "snr10")


def _answers_right(report: Report) -> dict[str, float]:
    return {c: report.answers(c).rate("right") for c in CONDITIONS}


def test_heard_answers_stay_at_the_measured_figures(report: Report) -> None:
    # Then answers are right as measured (66 and 62 of 67: 98.5% clean, 92.5% at 10 dB), and
    # never taken for the other weather
    right = {c: report.answers(c).counts["right"] for c in CONDITIONS}
    assert right["clean"] >= 66 and right["snr10"] >= 62, right
    assert all(report.answers(c).counts["wrong"] == 0 for c in CONDITIONS)


def test_heard_answers_meet_the_targets(report: Report) -> None:
    # Then answers are right >= 95% clean, >= 85% at 10 dB
    rates = _answers_right(report)
    assert rates["clean"] >= 0.95 and rates["snr10"] >= 0.85, rates


def test_unrelated_speech_stays_at_the_measured_figure(report: Report) -> None:
    # Then unrelated speech is taken for an answer no more often than measured (2 of 140)
    assert report.unrelated().counts["wrong"] <= 2, report.unrelated().to_json()


def test_unrelated_speech_is_rarely_taken_for_an_answer(report: Report) -> None:
    # Then unrelated speech is taken for an answer at most 2% of the time
    assert report.unrelated().rate("wrong") <= 0.02
