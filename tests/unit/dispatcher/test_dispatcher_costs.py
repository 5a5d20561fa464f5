"""The cost model's counts for one dispatched task (infra/cost_estimate.py `DispatchUsage`)
are what the dispatcher really does: measured on the handler under moto, with the fleet
index on boto3's wire."""

from __future__ import annotations

import pytest
from moto import mock_aws

from infra.cost_estimate import DispatchUsage, Prices, dispatch_billable, status_billable
from tests.support.dispatch_meter import measure_dispatch


@pytest.mark.parametrize("robots", [10, 250])
def test_a_task_costs_the_modelled_table_units_and_one_search_page_whatever_the_fleet(
    aws_credentials: None, robots: int
) -> None:
    with mock_aws():
        measured = measure_dispatch(robots)
    usage = DispatchUsage()
    # The table's units do not depend on the fleet's size
    assert measured.submit.reads + measured.freed.reads == usage.table_reads
    assert measured.submit.writes + measured.freed.writes == usage.table_writes
    # Candidates: one SearchIndex page of idle robots however many, and no shadow read
    assert measured.submit.calls["SearchIndex"] == 1
    assert measured.freed.calls["SearchIndex"] == 0
    assert "GetThingShadow" not in measured.submit.calls + measured.freed.calls
    # The schedule saw the robot with it once: one search, the acknowledgment marked
    assert measured.tick.calls["SearchIndex"] == usage.ack_searches
    assert measured.tick.calls["UpdateItem"] == 1 and measured.tick.writes == usage.ack_writes
    # One command published, to the robot that took the task
    assert measured.submit.calls["Publish"] == 1 and measured.freed.calls["Publish"] == 0
    assert dispatch_billable(robots, index=True).index_queries == 1 + usage.ack_searches


def test_the_index_is_cheaper_than_reading_every_shadow_from_a_few_hundred_robots() -> None:
    prices = Prices()
    for robots in (1_000, 10_000):
        assert dispatch_billable(robots, index=True).cost(prices) < dispatch_billable(
            robots, index=False
        ).cost(prices)
        assert status_billable(robots, index=True).cost(prices) < status_billable(
            robots, index=False
        ).cost(prices)
    # A status question about 10,000 robots: 3 queries against 20,000 shadow operations
    assert status_billable(10_000, index=True).index_queries == 3
    assert status_billable(10_000, index=False).shadow_operations == 20_000
