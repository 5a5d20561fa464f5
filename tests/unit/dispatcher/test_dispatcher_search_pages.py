"""How many pages of the fleet index the dispatcher function reads, through its handler:
one page of idle robots for a plain order, every page where a robot the order needs may be
on any (a group's members, the robots in a zone, a queued group task at the schedule).

The fleet index answers boto3's `iot` client with AWS's 100-thing pages, sorted by name
(the local data plane's); 150 idle rovers named `a-rover...` fill the first page and a half,
so the fleet's own placebot1 and placebot2 are on the second.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import boto3
import pytest

from dispatcher import app
from dispatcher.command_channel import CommandChannel
from dispatcher.fleet_search import FleetSearch
from tests.support.dispatch_meter import REGION, load_event
from tests.unit.dispatcher.test_dispatcher_handler import Index
from vahr.dispatch import Dispatcher
from vahr.domain import load_fleet
from vahr.domain.fleet import FLEET_GROUP

if TYPE_CHECKING:
    from collections.abc import Iterator

    from dispatcher.task_table import TaskTable


@pytest.fixture
def index() -> Iterator[Index]:
    served = Index()
    for n in range(150):
        served.report(f"a-rover{n:03}", status="idle", zone="D", pose={"x": 30.0, "y": 30.0})
    served.report("placebot1", status="idle", zone="A", pose={"x": 1.0, "y": 1.0})
    served.report("placebot2", status="idle", zone="B", pose={"x": 9.0, "y": 1.0})
    yield served
    served.server.stop()


class Function:
    def __init__(self, table: TaskTable, index: Index) -> None:
        self.searches: list[str] = []
        iot = boto3.client("iot", endpoint_url=index.server.url)
        iot.meta.events.register(
            "provide-client-params.iot.SearchIndex",
            lambda params, **_: self.searches.append(params["queryString"]),
        )
        self.dispatcher = Dispatcher(
            fleet=load_fleet(),
            store=table,
            candidates=FleetSearch(client=iot, holding=table.holders),
            publish=CommandChannel(client=boto3.client("iot-data", region_name=REGION)),
        )

    def __call__(self, event: dict[str, Any]) -> dict[str, Any]:
        self.searches.clear()
        return app.handle(event, self.dispatcher)

    def submit(self, **order: Any) -> dict[str, Any]:
        answer = self({"operation": "submit", "order": order})
        assert answer["status"] == 200, answer
        return answer["body"]  # type: ignore[no-any-return]


@pytest.fixture
def function(table: TaskTable, index: Index, dynamodb: Any) -> Function:
    return Function(table, index)


def test_a_plain_order_reads_one_page_of_idle_robots(function: Function) -> None:
    [task] = function.submit(zone="D")["assigned"]
    assert len(function.searches) == 1 and "status:idle" in function.searches[0]
    assert task["thing"].startswith("a-rover")


def test_a_groups_members_on_a_later_page_are_found(function: Function) -> None:
    # When every robot of the fleet (placebot1, placebot2: on the second page) is sent
    answer = function.submit(zone="C", group=FLEET_GROUP)
    # Then both go, none waits: both pages were read for each member's task
    assert sorted(task["thing"] for task in answer["assigned"]) == ["placebot1", "placebot2"]
    assert answer["queued"] == [] and len(function.searches) == 2 * 2


def test_the_robots_in_a_zone_are_each_given_their_task(function: Function) -> None:
    answer = function.submit(zone="C", origin="A")
    assert [task["thing"] for task in answer["assigned"]] == ["placebot1"]
    assert answer["queued"] == []


def test_the_schedule_finds_a_queued_members_robot_on_a_later_page(
    function: Function, index: Index
) -> None:
    # Given placebot2 stuck when its group was sent, so its task waits for it
    index.report("placebot2", status="stuck", zone="B")
    answer = function.submit(zone="C", group=FLEET_GROUP)
    [waiting] = answer["queued"]
    # When placebot2 is idle again but its rule event was lost
    index.report("placebot2", status="idle", zone="B", pose={"x": 9.0, "y": 1.0})
    tick = function(load_event("eventbridge_schedule"))
    # Then the schedule reads on to the page holding placebot2 and gives it its task
    assert tick["given"] == [waiting["id"]]
