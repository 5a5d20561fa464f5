"""The participant model's constants and operators: each constant cites its source."""

from __future__ import annotations

import math
import random
import re

import pytest

from vahr.experiment import timing

PUBLISHED = re.compile(r"\(\d{4}\)|\b(19|20)\d{2}\b")


def test_every_constant_of_the_model_carries_a_source() -> None:
    # Given every constant the timing module defines
    constants = {
        name: value for name, value in vars(timing).items() if isinstance(value, timing.Constant)
    }
    assert constants == timing.CONSTANTS and len(constants) >= 12
    for name, constant in constants.items():
        # Then each has a unit and a source: a dated publication, the paper, or the
        # station layout it assumes (which docs/experiment.md states)
        assert constant.unit, name
        assert constant.source.strip(), name
        assert (
            PUBLISHED.search(constant.source)
            or "Table II" in constant.source
            or "assumed station layout" in constant.source
        ), f"{name}: {constant.source!r}"


def test_the_puzzle_rate_is_the_papers_parts_over_neglect_time() -> None:
    assert timing.PUZZLE_RATE.value == pytest.approx((13 + 8) / (142 + 59))
    parts = [timing.puzzle_part_s(random.Random(seed)) for seed in range(4000)]
    assert sum(parts) / len(parts) == pytest.approx(201 / 21, rel=0.05)


def test_pointing_follows_fitts_law_with_the_mouse_coefficients() -> None:
    # 400 px to a 32 px wide target: ID = log2(400/32 + 1) bits
    assert timing.fitts_s(400, 32) == pytest.approx(-0.107 + 0.223 * math.log2(400 / 32 + 1))
    average = timing.Person()
    # A zone of fleet.yaml (1 m across) 8 m away on the map drawn at 80 px/m
    assert average.point_s((0, 0), (8 * 80, 0), 1.0) == pytest.approx(
        -0.107 + 0.223 * math.log2(8 + 1)
    )


def test_operators_follow_the_klm_and_the_speech_rates() -> None:
    average = timing.Person()
    assert (average.mental_s(), average.homing_s(), average.click_s()) == (1.35, 0.4, 0.2)
    # "Alexa, ask robot fleet what is the weather": 8 words at 150 per minute
    assert average.speaking_s("Alexa, ask robot fleet what is the weather") == pytest.approx(3.2)
    assert timing.listening_s("The weather is sunny.") == pytest.approx(4 * 60 / 175)
    assert average.glance_s() == pytest.approx(2 * 0.23 + 0.10 + 0.07)


def test_a_participant_is_drawn_from_the_seed_and_scales_every_human_operator() -> None:
    first, again = timing.Person.draw(random.Random(7)), timing.Person.draw(random.Random(7))
    assert first == again and first.tempo != timing.Person.draw(random.Random(8)).tempo
    assert first.mental_s() == pytest.approx(1.35 * first.tempo)
    tempos = [timing.Person.draw(random.Random(s)).tempo for s in range(3000)]
    spread = (sum(math.log(t) ** 2 for t in tempos) / len(tempos)) ** 0.5
    assert spread == pytest.approx(0.21, rel=0.1)
