"""The paper's formulas: RAD, fan-out, trust-adjusted RAD, rates and the TLX conversion."""

from __future__ import annotations

import pytest

from vahr.experiment.metrics import fan_out, rad, rate, trust_adjusted_rad
from vahr.experiment.tlx import TlxAnswers, check_level, to_percent


@pytest.mark.parametrize(
    ("ie", "nt", "time_taken", "want_rad", "want_fan_out"),
    [(111, 142, 254, 0.44, 578), (175, 59, 234, 0.75, 314)],
)
def test_the_papers_table_two_reproduces(
    ie: float, nt: float, time_taken: float, want_rad: float, want_fan_out: float
) -> None:
    # Given the paper's Table II averages (voice, then keyboard and mouse)
    # When RAD and fan-out are computed from them
    attention = rad(ie, nt)
    # Then RAD rounds to the paper's value and fan-out is within 1 % of it
    assert round(attention, 2) == want_rad
    assert fan_out(time_taken, attention) == pytest.approx(want_fan_out, rel=0.01)


def test_rad_is_the_share_of_time_spent_interacting() -> None:
    assert rad(30, 90) == 0.25
    assert rad(10, 0) == 1.0
    assert rad(0, 10) == 0.0


@pytest.mark.parametrize(("ie", "nt"), [(0, 0), (-1, 5), (5, float("nan")), (float("inf"), 1)])
def test_rad_refuses_undefined_input(ie: float, nt: float) -> None:
    with pytest.raises(ValueError, match="RAD|seconds"):
        rad(ie, nt)


def test_fan_out_refuses_a_rad_of_zero() -> None:
    with pytest.raises(ValueError, match=r"\(0, 1\]"):
        fan_out(100, 0)


def test_trust_adjusted_rad_charges_neglect_time_by_distrust() -> None:
    # DIT + NT x (1 - Tr)
    assert trust_adjusted_rad(100, 200, 0.75) == 150
    assert trust_adjusted_rad(100, 200, 1.0) == 100
    assert trust_adjusted_rad(100, 200, 0.0) == 300
    with pytest.raises(ValueError, match="trust"):
        trust_adjusted_rad(100, 200, 1.5)


def test_rate_is_none_when_nothing_was_attempted() -> None:
    assert rate(3, 4) == 0.75
    assert rate(0, 0) is None
    with pytest.raises(ValueError):
        rate(5, 4)


@pytest.mark.parametrize(("level", "percent"), [(1, 0.0), (11, 50.0), (21, 100.0), (2, 5.0)])
def test_tlx_levels_convert_exactly(level: int, percent: float) -> None:
    assert to_percent(level) == percent


@pytest.mark.parametrize("level", [0, 22, 3.5, "x", True, None])
def test_tlx_rejects_levels_outside_the_scale(level: object) -> None:
    with pytest.raises(ValueError, match="levels are 1 to 21"):
        check_level("mental", level)


def test_tlx_answers_need_all_eight_items() -> None:
    levels = dict(
        mental=11,
        physical=1,
        temporal=21,
        performance=5,
        effort=6,
        frustration=7,
        confidence=18,
        trust=19,
    )
    answers = TlxAnswers.from_mapping(levels)
    assert answers.percents()["temporal"] == 100.0
    assert answers.raw_tlx() == pytest.approx((50 + 0 + 100 + 20 + 25 + 30) / 6)
    levels.pop("trust")
    with pytest.raises(ValueError, match="missing answers for trust"):
        TlxAnswers.from_mapping(levels)
    with pytest.raises(ValueError, match="fun: not a questionnaire item"):
        TlxAnswers.from_mapping({**levels, "trust": 3, "fun": 4})
