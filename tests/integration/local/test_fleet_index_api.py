"""The local fleet index as boto3's unmodified `iot` client sees it: search_index,
get_buckets_aggregation and get_statistics against the local data plane, answered in the
shapes AWS returns, with AWS's exceptions for bad queries. Robots report over MQTT, as
real ones do, so the index is tested as the shadow service keeps it."""

from __future__ import annotations

import json
import threading
from typing import TYPE_CHECKING, Any

import boto3
import pytest

from tests.integration.local.shadow_clients import unique_thing
from vahr.plumbing.mqtt import MqttClient
from vahr.protocol import topics

if TYPE_CHECKING:
    from vahr.twin.stack import LocalStack


@pytest.fixture
def iot(local_stack: LocalStack, aws_credentials: None, monkeypatch: pytest.MonkeyPatch) -> Any:
    # The variable boto3 itself reads for the control plane.
    monkeypatch.setenv("AWS_ENDPOINT_URL_IOT", local_stack.api_url)
    return boto3.client("iot")


@pytest.fixture
def fleet(local_stack: LocalStack) -> dict[str, str]:
    """Three robots with one prefix, reporting over MQTT: idle, idle, stuck."""
    prefix = unique_thing()
    statuses = {f"{prefix}a": "idle", f"{prefix}b": "idle", f"{prefix}c": "stuck"}
    accepted = threading.Semaphore(0)
    with MqttClient(local_stack.service_endpoint()) as robot:
        for thing in statuses:
            robot.subscribe(
                topics.shadow(thing, "update/accepted"), lambda _t, _p: accepted.release()
            )
        for thing, status in statuses.items():
            report = {"state": {"reported": {"status": status, "zone": "C", "connected": True}}}
            robot.publish(topics.shadow(thing, "update"), json.dumps(report).encode(), qos=1)
        for _ in statuses:
            assert accepted.acquire(timeout=5)
    return {"prefix": prefix, **statuses}


def test_search_index_finds_robots_by_reported_status(iot: Any, fleet: dict[str, str]) -> None:
    prefix = fleet["prefix"]
    found = iot.search_index(
        indexName="AWS_Things",
        queryString=f"thingName:{prefix}* AND shadow.reported.status:idle",
    )
    assert [thing["thingName"] for thing in found["things"]] == [f"{prefix}a", f"{prefix}b"]
    document = found["things"][0]
    assert json.loads(document["shadow"])["reported"]["zone"] == "C"
    assert document["connectivity"]["connected"] is True


def test_search_index_pages_with_next_token(iot: Any, fleet: dict[str, str]) -> None:
    query = f"thingName:{fleet['prefix']}*"
    first = iot.search_index(queryString=query, maxResults=2)
    second = iot.search_index(queryString=query, maxResults=2, nextToken=first["nextToken"])
    assert len(first["things"]) == 2
    assert [thing["thingName"] for thing in second["things"]] == [f"{fleet['prefix']}c"]
    assert "nextToken" not in second


def test_buckets_aggregation_counts_by_status(iot: Any, fleet: dict[str, str]) -> None:
    answer = iot.get_buckets_aggregation(
        queryString=f"thingName:{fleet['prefix']}*",
        aggregationField="shadow.reported.status",
        bucketsAggregationType={"termsAggregation": {"maxBuckets": 10}},
    )
    assert answer["totalCount"] == 3
    assert answer["buckets"] == [
        {"keyValue": "idle", "count": 2},
        {"keyValue": "stuck", "count": 1},
    ]


def test_statistics_count_the_matching_things(iot: Any, fleet: dict[str, str]) -> None:
    answer = iot.get_statistics(
        queryString=f"thingName:{fleet['prefix']}* NOT shadow.reported.status:idle"
    )
    assert answer["statistics"]["count"] == 1


def test_a_bad_query_is_invalid_query_exception_in_one_line(iot: Any) -> None:
    with pytest.raises(iot.exceptions.InvalidQueryException) as caught:
        iot.search_index(queryString="shadow.reported.status:idle AND (")
    message = caught.value.response["Error"]["Message"]
    assert "Syntax error in query" in message and "\n" not in message


def test_an_unknown_field_and_index_are_refused(iot: Any) -> None:
    with pytest.raises(
        iot.exceptions.InvalidQueryException, match="Unsupported field 'attributes.x'"
    ):
        iot.get_statistics(queryString="attributes.x:1")
    with pytest.raises(iot.exceptions.InvalidAggregationException):
        iot.get_buckets_aggregation(
            queryString="thingName:*",
            aggregationField="thingName",
            bucketsAggregationType={"termsAggregation": {}},
        )
    with pytest.raises(iot.exceptions.ResourceNotFoundException):
        iot.search_index(indexName="AWS_ThingGroups", queryString="thingName:*")
