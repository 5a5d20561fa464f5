"""The modelled AWS cost of one announcement (infra/cost_estimate.py)."""

from __future__ import annotations

import pytest

from infra.cost_estimate import (
    AnnouncerTicks,
    AnnouncerUsage,
    Prices,
    announcement_cost,
    announcer_ticks_cost,
)


def test_one_invocation_costs_its_rule_function_state_and_logs() -> None:
    # Given one invocation per announcement, never a cold start
    usage = AnnouncerUsage(invocations_per_announcement=1, cold_start_share=0)
    prices = Prices()
    # Then: rule + action, request, 0.075 GB-s, one read, one write, 1 KB of logs, and the
    # station's topic: the publish and its delivery
    expected = (0.15 + 0.15 + 0.20 + 0.625 + 0.125) / 1e6 + 0.075 * 0.0000166667 + 1e-6 * 0.5
    assert announcement_cost(prices, usage) == pytest.approx(expected + 2 * 1e-6)


def test_an_announcement_costs_about_sixteen_dollars_a_million() -> None:
    cost = announcement_cost(Prices())
    assert cost == pytest.approx(1.6e-5, rel=0.01)  # USD 16 per million announcements


def test_the_schedule_costs_a_few_cents_a_month() -> None:
    # Given a tick a minute for 30 days, each a request, 12.5 ms-GB, one read, 200 B of logs
    per_tick = (0.20 + 0.125) / 1e6 + 0.0125 * 0.0000166667 + 200e-9 * 0.5
    # Then the month costs 43,200 of those: under three cents
    assert announcer_ticks_cost(Prices()) == pytest.approx(43_200 * per_tick)
    assert announcer_ticks_cost(Prices()) < 0.03
    assert AnnouncerTicks().per_month == 43_200
