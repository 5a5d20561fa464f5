"""The local data plane as boto3's unmodified iot-data client sees it: Publish reaches the
broker with QoS and retain honoured, named shadows are listed page by page, and the local
stack's own routes answer."""

from __future__ import annotations

import json
import threading
import urllib.request
from typing import TYPE_CHECKING, Any

import boto3
import pytest

from tests.integration.local.shadow_clients import unique_thing
from vahr.plumbing.mqtt import MqttClient

if TYPE_CHECKING:
    from vahr.twin.stack import LocalStack


@pytest.fixture
def iot_data(
    local_stack: LocalStack, aws_credentials: None, monkeypatch: pytest.MonkeyPatch
) -> Any:
    # The variable boto3 itself reads, so the client is built exactly as the skill builds it.
    monkeypatch.setenv("AWS_ENDPOINT_URL_IOT_DATA_PLANE", local_stack.api_url)
    return boto3.client("iot-data")


def test_publish_reaches_subscribers_and_retain_is_kept(
    local_stack: LocalStack, iot_data: Any
) -> None:
    topic = f"vahr/robots/{unique_thing()}/presence"
    # When the data plane publishes a retained message
    iot_data.publish(topic=topic, qos=1, retain=True, payload=b'{"online":true}')
    # Then a subscriber that arrives later still receives it
    got: list[bytes] = []
    arrived = threading.Event()
    with MqttClient(local_stack.service_endpoint()) as late:
        late.subscribe(topic, lambda _t, p: (got.append(p), arrived.set()))
        assert arrived.wait(5)
    assert got == [b'{"online":true}']


def test_publish_without_retain_is_not_kept(local_stack: LocalStack, iot_data: Any) -> None:
    topic = f"vahr/robots/{unique_thing()}/events"
    iot_data.publish(topic=topic, qos=0, payload=b"{}")
    arrived = threading.Event()
    with MqttClient(local_stack.service_endpoint()) as late:
        late.subscribe(topic, lambda _t, _p: arrived.set())
        assert not arrived.wait(0.3)


def test_named_shadows_are_listed_page_by_page(iot_data: Any) -> None:
    thing = unique_thing()
    for name in ("a", "b", "c"):
        iot_data.update_thing_shadow(
            thingName=thing, shadowName=name, payload=b'{"state":{"reported":{"x":1}}}'
        )
    first = iot_data.list_named_shadows_for_thing(thingName=thing, pageSize=2)
    assert first["results"] == ["a", "b"]
    second = iot_data.list_named_shadows_for_thing(
        thingName=thing, pageSize=2, nextToken=first["nextToken"]
    )
    assert second["results"] == ["c"]
    assert "nextToken" not in second


def test_a_bad_thing_name_is_an_invalid_request(iot_data: Any) -> None:
    with pytest.raises(iot_data.exceptions.InvalidRequestException):
        iot_data.get_thing_shadow(thingName="not a thing")


def test_the_meter_counts_billable_operations(local_stack: LocalStack, iot_data: Any) -> None:
    thing = unique_thing()
    before = local_stack.meter.snapshot()["operations"]
    iot_data.update_thing_shadow(thingName=thing, payload=b'{"state":{"reported":{"x":1}}}')
    iot_data.get_thing_shadow(thingName=thing)
    iot_data.publish(topic=f"vahr/robots/{thing}/cmd", qos=1, payload=b"{}")
    with urllib.request.urlopen(f"{local_stack.api_url}/vahr/meter", timeout=5) as response:
        after = json.loads(response.read())["operations"]
    for kind in ("http.shadow.update", "http.shadow.get", "http.publish"):
        assert after[kind] == before.get(kind, 0) + 1
