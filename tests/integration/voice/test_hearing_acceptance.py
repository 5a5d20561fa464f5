"""Acceptance of the robot's hearing (issue 13) on a fixed sample of the spoken evaluation
set: every other sentence of `robot_agent/voice/data/hearing-eval.yaml`, in the room
assistant's voice (en-us+f4), clean, at 20 dB and at 10 dB SNR (180 clips, rendered with
the set's seed, so the same on every run). `bench/hearing.py` scores the whole set.

The targets are not reached yet (docs/voice.md, "How well it hears"): the test is an
expected failure until they are, and fails outright (strict) the day they are met, so the
marker is then removed."""

from __future__ import annotations

import time
from typing import TYPE_CHECKING

import pytest

from robot_agent.voice.evaluation import EVALUATION_SET, Phrasings, render, score
from vahr.speech.tts import EspeakSynthesizer

if TYPE_CHECKING:
    from pathlib import Path

    from robot_agent.voice.understanding import Understanding

pytestmark = pytest.mark.slow


def sample_of(phrasings: Phrasings) -> Phrasings:
    return Phrasings(
        voices=["en-us+f4"],
        snr_db=phrasings.snr_db,
        seed=phrasings.seed,
        answers={intent: texts[::2] for intent, texts in phrasings.answers.items()},
        unrelated=phrasings.unrelated[::2],
    )


@pytest.mark.xfail(strict=True, reason="issue 13's hearing targets are not reached yet")
def test_heard_answers_meet_the_targets_on_the_sample(
    understanding: Understanding, tmp_path: Path
) -> None:
    # Given the fixed sample of the evaluation set, rendered as `--make-eval-set` does
    render(sample_of(Phrasings.load(EVALUATION_SET)), tmp_path, EspeakSynthesizer)
    # When the robot hears every clip
    report = score(tmp_path, understanding.hear, time.perf_counter)
    # Then answers are right >= 95% clean and at 20 dB, >= 85% at 10 dB, and unrelated
    # speech is taken for an answer at most 2% of the time
    rates = {c: report.answers(c).rate("right") for c in ("clean", "snr20", "snr10")}
    assert rates["clean"] >= 0.95 and rates["snr20"] >= 0.95 and rates["snr10"] >= 0.85, rates
    assert report.unrelated().rate("wrong") <= 0.02
