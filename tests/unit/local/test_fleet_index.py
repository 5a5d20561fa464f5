"""The local fleet index: kept by the shadow store on every change of a classic shadow,
and queried by status, zone, name prefix and AWS's query syntax."""

from __future__ import annotations

import json

import pytest

from vahr.twin.fleet_index import AggregationError
from vahr.twin.fleet_query import QueryError, parse
from vahr.twin.shadow_store import ShadowStore


def _report(store: ShadowStore, thing: str, **reported: object) -> None:
    store.update(thing, None, json.dumps({"state": {"reported": reported}}).encode())


@pytest.fixture
def store() -> ShadowStore:
    store = ShadowStore(clock=lambda: 1_800_000_000.0)
    _report(store, "rover1", status="idle", zone="A", connected=True, pose={"x": 1, "y": 2},
            battery={"percent": 12, "charging": False})  # fmt: skip
    _report(store, "rover2", status="navigating", zone="B", connected=True,
            battery={"percent": 20, "charging": True})  # fmt: skip
    _report(store, "rover10", status="stuck", zone="C", connected=True,
            battery={"percent": 80})  # fmt: skip
    _report(store, "placebot1", status="idle", zone="A", connected=False)
    return store


def names(things: list) -> list[str]:  # type: ignore[type-arg]
    return [thing.thing for thing in things]


def test_each_update_moves_the_robot_between_statuses_and_zones(store: ShadowStore) -> None:
    _report(store, "rover1", status="navigating", zone=None)
    index = store.index
    assert names(index.with_status("idle")) == ["placebot1"]
    assert names(index.with_status("navigating")) == ["rover1", "rover2"]
    assert names(index.in_zone("A")) == ["placebot1"]
    assert index.status_counts() == {"idle": 1, "navigating": 2, "stuck": 1}
    # The pose reported before stays: an update merges into the shadow.
    entry = index.get("rover1")
    assert entry is not None and entry.pose is not None and (entry.pose.x, entry.pose.y) == (1, 2)
    assert entry.updated_at == 1_800_000_000


def test_named_shadows_are_not_robots_and_a_deleted_shadow_leaves(store: ShadowStore) -> None:
    store.update("rover2", "task", b'{"state":{"reported":{"status":"stuck"}}}')
    assert store.index.status_counts()["stuck"] == 1
    store.delete("rover2")
    assert store.index.get("rover2") is None
    assert names(store.index.with_prefix("rover")) == ["rover1", "rover10"]


def test_the_index_is_rebuilt_from_the_database_after_a_restart(tmp_path) -> None:  # type: ignore[no-untyped-def]
    database = tmp_path / "shadows.db"
    first = ShadowStore(database)
    _report(first, "rover7", status="stuck", zone="D", connected=True)
    first.close()
    again = ShadowStore(database)
    assert names(again.index.with_status("stuck")) == ["rover7"]
    assert names(again.index.in_zone("D")) == ["rover7"]


@pytest.mark.parametrize(
    ("query", "expected"),
    [
        ("shadow.reported.status:idle", ["placebot1", "rover1"]),
        ("shadow.reported.status:idle AND connectivity.connected:true", ["rover1"]),
        ("shadow.reported.status:idle connectivity.connected:false", ["placebot1"]),
        ("shadow.reported.zone:B OR shadow.reported.zone:C", ["rover10", "rover2"]),
        ("thingName:rover1*", ["rover1", "rover10"]),
        ("thingName:rover1", ["rover1"]),
        ("NOT shadow.reported.status:idle", ["rover10", "rover2"]),
        (
            "thingName:rover* AND NOT (shadow.reported.zone:A OR shadow.reported.zone:B)",
            ["rover10"],
        ),
        ("shadow.reported.status:nav*", ["rover2"]),
        ('shadow.reported.zone:"C"', ["rover10"]),
        ("shadow.reported.status:*", ["placebot1", "rover1", "rover10", "rover2"]),
        ("shadow.reported.status:flying", []),
        # The charge by range, in both of AWS's forms, and whether it charges
        ("shadow.reported.battery.percent<20", ["rover1"]),
        ("shadow.reported.battery.percent<=20", ["rover1", "rover2"]),
        ("shadow.reported.battery.percent>20", ["rover10"]),
        ("shadow.reported.battery.percent>=12.5", ["rover10", "rover2"]),
        ("shadow.reported.battery.percent:[12 TO 20]", ["rover1", "rover2"]),
        ("shadow.reported.battery.percent:{12 TO 20]", ["rover2"]),
        ("shadow.reported.battery.percent:[12 TO 20}", ["rover1"]),
        ("shadow.reported.battery.percent:[50 TO *]", ["rover10"]),
        ("shadow.reported.battery.percent:20", ["rover2"]),
        ("shadow.reported.battery.percent:*", ["rover1", "rover10", "rover2"]),
        ("NOT shadow.reported.battery.percent:*", ["placebot1"]),
        ("shadow.reported.battery.charging:true", ["rover2"]),
        ("shadow.reported.battery.charging:false", ["rover1"]),
        (
            "(shadow.reported.status:idle OR shadow.reported.status:stuck) "
            "AND shadow.reported.connected:true AND shadow.reported.battery.percent<90",
            ["rover1", "rover10"],
        ),
    ],
)
def test_queries_in_aws_syntax(store: ShadowStore, query: str, expected: list[str]) -> None:
    assert names(store.index.search(query)) == expected


def test_buckets_count_by_status_largest_first(store: ShadowStore) -> None:
    total, buckets = store.index.buckets("thingName:*", "shadow.reported.status")
    assert total == 4
    assert buckets == [("idle", 2), ("navigating", 1), ("stuck", 1)]
    assert store.index.buckets("thingName:*", "shadow.reported.status", 1)[1] == [("idle", 2)]
    assert store.index.statistics("shadow.reported.zone:A") == 2


@pytest.mark.parametrize(
    ("query", "message"),
    [
        ("", "The query string is empty"),
        ("status:idle", "Unsupported field 'status'"),
        ("shadow.reported.status:idle AND", "it ends where a term was expected"),
        ("(shadow.reported.status:idle", "a '(' is never closed"),
        ("shadow.reported.status:id*le", "Wildcards are supported only at the end"),
        ("connectivity.connected:maybe", "takes true or false"),
        ("idle", "expected field:value"),
        ("shadow.reported.status:idle)", "Syntax error in query near ')'"),
        ("shadow.reported.battery.percent<low", "takes a number, not 'low'"),
        ("shadow.reported.battery.percent:2*", "takes a number, not '2*'"),
        ("shadow.reported.battery.percent:[0 TO]", "expected [low TO high]"),
        ("shadow.reported.battery.charging:yes", "takes true or false"),
        ("shadow.reported.zone<5", "ranges are answered on shadow.reported.battery.percent"),
        ("shadow.reported.zone:[A TO C]", "ranges are answered on shadow.reported.battery.percent"),
    ],
)
def test_a_bad_query_is_one_line_naming_the_problem(query: str, message: str) -> None:
    with pytest.raises(QueryError) as caught:
        parse(query)
    assert message in str(caught.value)
    assert "\n" not in str(caught.value)


def test_an_aggregation_over_a_field_not_kept_is_refused(store: ShadowStore) -> None:
    with pytest.raises(AggregationError, match="Unsupported aggregation field 'thingName'"):
        store.index.buckets("thingName:*", "thingName")


def test_who_acknowledged_a_command_is_a_query_not_a_read_per_robot(store: ShadowStore) -> None:
    _report(store, "rover1", last_command={"id": "c-7", "action": "navigate", "result": "accepted"})
    _report(store, "rover2", last_command={"id": "c-7", "action": "navigate", "result": "rejected"})
    _report(store, "rover10", last_command={"id": "c-6", "action": "navigate", "result": "done"})
    index = store.index
    assert names(index.search("shadow.reported.last_command.id:c-7")) == ["rover1", "rover2"]
    silent = "thingName:rover* AND NOT shadow.reported.last_command.id:c-7"
    assert names(index.search(silent)) == ["rover10"]
    total, buckets = index.buckets(
        "shadow.reported.last_command.id:c-7", "shadow.reported.last_command.result"
    )
    assert (total, buckets) == (2, [("accepted", 1), ("rejected", 1)])
    # A robot's next command moves it from one id to the other.
    _report(
        store, "rover10", last_command={"id": "c-7", "action": "navigate", "result": "accepted"}
    )
    assert index.statistics("shadow.reported.last_command.id:c-7") == 3
    assert index.statistics("shadow.reported.last_command.id:c-6") == 0
