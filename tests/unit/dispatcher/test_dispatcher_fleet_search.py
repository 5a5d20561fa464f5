"""The Candidates adapter on fleet indexing's SearchIndex, against a fleet index that answers
boto3's `iot` client with AWS's shapes and pagination (the local data plane's).

moto's own `search_index` cannot stand in here: it matches only thing names, types, groups
and attributes (a `shadow.reported.*` term matches nothing), ignores `maxResults` and never
pages. What neither can show is AWS's indexing delay (seconds) and its exact query parser;
the adapter sends only field:value terms, OR and AND, and one range on a number field
(`field<20`), all of which AWS's query syntax documents.
"""

from __future__ import annotations

import json
from typing import TYPE_CHECKING, Any

import boto3
import pytest

from dispatcher.errors import SearchError
from dispatcher.fleet_search import FleetSearch, available_query, low_query
from vahr.domain.fleet import Pose
from vahr.protocol.shadow import Battery
from vahr.twin.dataplane import DataPlane, DataPlaneServer
from vahr.twin.meter import Meter
from vahr.twin.shadow_service import ShadowService
from vahr.twin.shadow_store import ShadowStore

if TYPE_CHECKING:
    from collections.abc import Iterator

    from vahr.dispatch import RobotState


@pytest.fixture
def fleet_index(aws_credentials: None) -> Iterator[tuple[ShadowStore, Any]]:
    store = ShadowStore(None)
    shadows = ShadowService(store, publish=lambda _topic, _payload: None)
    with DataPlaneServer(DataPlane(shadows, publish=lambda *_: None, meter=Meter()), 0) as server:
        yield store, boto3.client("iot", endpoint_url=server.url)


def report(store: ShadowStore, thing: str, **reported: Any) -> None:
    store.update(thing, None, json.dumps({"state": {"reported": reported}}).encode())


def test_every_free_robot_is_found_across_pages_with_its_pose(
    fleet_index: tuple[ShadowStore, Any],
) -> None:
    store, iot = fleet_index
    # Given 230 robots that may take a task (three pages of 100) and 20 that may not
    for n in range(230):
        status = "idle" if n % 2 else "navigating"
        report(store, f"rover{n}", status=status, zone="A" if n < 30 else "B",
               connected=True, pose={"x": n, "y": 1.0})  # fmt: skip
    for n in range(230, 240):
        report(store, f"rover{n}", status="stuck", zone="A", connected=True)
    for n in range(240, 250):
        report(store, f"rover{n}", status="idle", zone="A", connected=False)
    calls: list[str] = []
    iot.meta.events.register("before-call.iot.SearchIndex", lambda **_: calls.append("search"))
    search = FleetSearch(client=iot)
    with search.every_robot():
        found = search.available()
    # Then all 230 come back, each with its reported state, in three SearchIndex calls
    assert len(found) == 230 and len(calls) == 3
    rover7 = next(robot for robot in found if robot.thing == "rover7")
    assert (rover7.status, rover7.zone, rover7.pose, rover7.idle) == (
        "idle",
        "A",
        Pose(7, 1.0),
        True,
    )
    # And a zone narrows the search itself
    in_a = FleetSearch(client=iot).available(zone="A")
    assert sorted(robot.thing for robot in in_a) == sorted(f"rover{n}" for n in range(30))


def test_one_robots_state_and_an_unknown_one(fleet_index: tuple[ShadowStore, Any]) -> None:
    store, iot = fleet_index
    report(store, "placebot1", status="idle", zone="C", connected=True,
           last_command={"id": "abc", "action": "navigate", "result": "done"})  # fmt: skip
    report(store, "placebot10", status="stuck", connected=True)
    search = FleetSearch(client=iot)
    state = search.state("placebot1")
    assert state is not None
    assert (state.last_command_id, state.last_result, state.available) == ("abc", "done", True)
    assert search.state("placebot9") is None


def test_the_query_names_every_status_that_may_take_a_task() -> None:
    assert available_query("C") == (
        "(shadow.reported.status:idle OR shadow.reported.status:loading OR "
        "shadow.reported.status:navigating OR shadow.reported.status:stopped OR "
        "shadow.reported.status:unloading OR shadow.reported.status:waiting) "
        "AND shadow.reported.connected:true AND shadow.reported.zone:C"
    )
    with pytest.raises(SearchError, match="cannot be searched for"):
        available_query("C OR thingName:*")


def test_an_index_that_does_not_answer_is_one_line(fleet_index: tuple[ShadowStore, Any]) -> None:
    _, iot = fleet_index
    with pytest.raises(
        SearchError, match=r"ResourceNotFoundException: Index AWS_Nope does not exist"
    ):
        FleetSearch(index_name="AWS_Nope", client=iot).available()


def searches(iot: Any) -> list[str]:
    """The query string of every SearchIndex call `iot` makes from now on."""
    queries: list[str] = []
    iot.meta.events.register(
        "provide-client-params.iot.SearchIndex",
        lambda params, **_: queries.append(params["queryString"]),
    )
    return queries


def test_a_search_for_a_task_reads_one_page_of_idle_robots_with_their_battery(
    fleet_index: tuple[ShadowStore, Any],
) -> None:
    store, iot = fleet_index
    # Given 250 idle robots (three pages) and 50 busy ones, each reporting its battery
    for n in range(300):
        status = "idle" if n < 250 else "navigating"
        report(store, f"rover{n:03}", status=status, connected=True,
               battery={"percent": n % 101, "charging": n % 2 == 0})  # fmt: skip
    queries = searches(iot)
    found = FleetSearch(client=iot).available()
    # Then one SearchIndex call, for connected idle robots, answers a page of idle robots
    assert queries == [
        "(shadow.reported.status:idle OR shadow.reported.status:stopped) "
        "AND shadow.reported.connected:true"
    ]
    assert len(found) == 100 and all(robot.idle for robot in found)
    rover7 = next(robot for robot in found if robot.thing == "rover007")
    assert rover7.battery == Battery(percent=7, charging=False)


def test_pages_of_robots_holding_tasks_are_read_past_then_the_busy_ones(
    fleet_index: tuple[ShadowStore, Any],
) -> None:
    store, iot = fleet_index
    # Given 150 idle robots that all hold a task, and 30 busy robots
    for n in range(180):
        report(store, f"rover{n:03}", status="idle" if n < 150 else "waiting", connected=True)
    holding = {f"rover{n:03}" for n in range(150)}
    queries = searches(iot)
    found = FleetSearch(client=iot, holding=lambda: holding).available()
    # Then both idle pages are read, then the one page of busy robots, which are the free
    assert len(queries) == 3 and "status:waiting" in queries[2]
    assert {robot.thing for robot in found} - holding == {f"rover{n:03}" for n in range(150, 180)}


def test_many_robots_states_are_read_in_few_searches_within_the_query_limit(
    fleet_index: tuple[ShadowStore, Any],
) -> None:
    store, iot = fleet_index
    for n in range(120):
        report(store, f"rover{n:03}", status="idle", connected=n % 2 == 0,
               last_command={"id": f"task{n}", "result": "accepted"})  # fmt: skip
    queries = searches(iot)
    states = FleetSearch(client=iot).states([f"rover{n:03}" for n in range(121)])
    # Then every known robot's state comes back (rover120 is unknown), in 3 searches
    assert len(states) == 120 and "rover120" not in states
    assert states["rover007"].last_command_id == "task7" and not states["rover007"].connected
    assert len(queries) == 3 and all(len(query) <= 1000 for query in queries)


def test_a_page_of_robots_the_dispatcher_would_not_use_is_read_past(
    fleet_index: tuple[ShadowStore, Any],
) -> None:
    store, iot = fleet_index
    # Given 100 idle robots almost empty, then 20 charged ones on the second page
    for n in range(120):
        report(store, f"rover{n:03}", status="idle", connected=True,
               battery={"percent": 5 if n < 100 else 90, "charging": False})  # fmt: skip
    queries = searches(iot)

    def charged(robot: RobotState) -> bool:
        return robot.battery is None or robot.battery.percent >= 20

    found = FleetSearch(client=iot, usable=charged).available()
    # Then the second page is read too, and the charged robots are among those found
    assert len(queries) == 2
    assert {robot.thing for robot in found if charged(robot)} == {
        f"rover{n:03}" for n in range(100, 120)
    }


def test_the_idle_robots_low_on_charge_are_one_search_however_many_are_idle(
    fleet_index: tuple[ShadowStore, Any],
) -> None:
    store, iot = fleet_index
    # Given 300 idle robots (three pages), four of them under 20 percent: one charging, one
    # offline, one busy beside them, and one at exactly 20
    for n in range(300):
        percent = {7: 5, 8: 19, 9: 3, 10: 12, 11: 20}.get(n, 60 + n % 40)
        report(store, f"rover{n:03}", status="navigating" if n == 10 else "idle",
               connected=n != 9, battery={"percent": percent, "charging": n == 8})  # fmt: skip
    queries = searches(iot)
    low = FleetSearch(client=iot).low_idle(20)
    # Then one SearchIndex call, a range on the indexed charge, finds the connected idle
    # ones under 20 percent (the charging one too: whether to send it is the dispatcher's)
    assert queries == [
        "(shadow.reported.status:idle OR shadow.reported.status:stopped) "
        "AND shadow.reported.connected:true AND shadow.reported.battery.percent<20"
    ]
    assert {robot.thing: robot.battery for robot in low} == {
        "rover007": Battery(percent=5, charging=False),
        "rover008": Battery(percent=19, charging=True),
    }
    assert low_query(12.5).endswith("shadow.reported.battery.percent<12.5")
