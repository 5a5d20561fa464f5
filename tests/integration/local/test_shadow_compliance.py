"""Device Shadow compliance: one set of cases over the local service's MQTT API, over the
local data plane with boto3, and against moto where moto models the behaviour (its known
gaps are strict xfails, so a fixed gap shows up as a failure to revisit)."""

from __future__ import annotations

import json
import time
from typing import TYPE_CHECKING

import boto3
import pytest
from moto import mock_aws

from tests.integration.local.shadow_clients import Boto3Shadows, MqttShadows, Shadows, unique_thing
from tests.support.fault_injection_steps import wait_until
from vahr.plumbing.mqtt import MqttClient
from vahr.protocol import topics

if TYPE_CHECKING:
    from collections.abc import Iterator

    from vahr.twin.stack import LocalStack

TRANSPORTS = ["mqtt", "http", "moto"]


@pytest.fixture(params=TRANSPORTS)
def shadows(
    request: pytest.FixtureRequest, local_stack: LocalStack, aws_credentials: None
) -> Iterator[Shadows]:
    if request.param == "mqtt":
        with MqttClient(local_stack.service_endpoint()) as client:
            yield MqttShadows(client)
    elif request.param == "http":
        yield Boto3Shadows("http", boto3.client("iot-data", endpoint_url=local_stack.api_url))
    else:
        with mock_aws():
            yield Boto3Shadows("moto", boto3.client("iot-data"), boto3.client("iot"))


@pytest.fixture
def thing(shadows: Shadows) -> str:
    name = unique_thing()
    shadows.prepare(name)
    return name


def moto_gap(request: pytest.FixtureRequest, shadows: Shadows, reason: str) -> None:
    """Mark a case where moto is known to differ from AWS (docs/local.md lists the gaps)."""
    if shadows.kind == "moto":
        request.applymarker(pytest.mark.xfail(strict=True, reason=f"moto gap: {reason}"))


def local_only(shadows: Shadows, reason: str) -> None:
    if shadows.kind == "moto":
        pytest.skip(f"moto does not model this: {reason}")


def body(value: object) -> bytes:
    return json.dumps(value).encode()


# -- creating, reading, versions ------------------------------------------------------


def test_first_update_creates_version_1_with_metadata(shadows: Shadows, thing: str) -> None:
    # When a robot reports its state for the first time
    reply = shadows.update(thing, body({"state": {"reported": {"status": "idle", "zone": "A"}}}))
    # Then the update is accepted as version 1 with a timestamp per reported key
    assert reply.status == 200
    assert reply.body["state"] == {"reported": {"status": "idle", "zone": "A"}}
    assert reply.body["version"] == 1
    metadata = reply.body["metadata"]["reported"]
    assert set(metadata) == {"status", "zone"}
    assert isinstance(metadata["zone"]["timestamp"], int)


def test_get_returns_the_merged_document_and_the_delta(shadows: Shadows, thing: str) -> None:
    shadows.update(thing, body({"state": {"reported": {"zone": "A", "cargo": False}}}))
    shadows.update(thing, body({"state": {"desired": {"zone": "B", "cargo": False}}}))
    reply = shadows.get(thing)
    assert reply.status == 200
    assert reply.body["state"]["reported"] == {"zone": "A", "cargo": False}
    assert reply.body["state"]["desired"] == {"zone": "B", "cargo": False}
    assert reply.body["state"]["delta"] == {"zone": "B"}
    assert reply.body["version"] == 2


def test_nested_objects_merge_key_by_key(shadows: Shadows, thing: str) -> None:
    shadows.update(thing, body({"state": {"reported": {"pose": {"x": 1, "y": 2}}}}))
    shadows.update(thing, body({"state": {"reported": {"pose": {"x": 5}}}}))
    assert shadows.get(thing).body["state"]["reported"] == {"pose": {"x": 5, "y": 2}}


def test_get_of_a_missing_shadow_is_404(shadows: Shadows, thing: str) -> None:
    reply = shadows.get(thing)
    assert reply.status == 404
    assert reply.error == "ResourceNotFoundException"
    if shadows.kind != "moto":
        assert reply.body["message"] == f"No shadow exists with name: '{thing}'"


def test_a_stale_version_is_rejected_with_409(shadows: Shadows, thing: str) -> None:
    shadows.update(thing, body({"state": {"reported": {"zone": "A"}}}))
    shadows.update(thing, body({"state": {"reported": {"zone": "B"}}}))
    # When an update says it was based on version 1 while the shadow is at version 2
    reply = shadows.update(thing, body({"state": {"reported": {"zone": "C"}}, "version": 1}))
    # Then it is refused and nothing changes
    assert reply.status == 409
    assert reply.error == "ConflictException"
    if shadows.kind != "moto":
        assert reply.body["message"] == "Version conflict"
    assert shadows.get(thing).body["state"]["reported"] == {"zone": "B"}
    # And the current version is accepted
    assert (
        shadows.update(thing, body({"state": {"reported": {"zone": "C"}}, "version": 2})).status
        == 200
    )


def test_client_token_is_echoed(
    request: pytest.FixtureRequest, shadows: Shadows, thing: str
) -> None:
    moto_gap(request, shadows, "clientToken is not echoed")
    reply = shadows.update(
        thing, body({"state": {"reported": {"zone": "A"}}, "clientToken": "cmd-42"})
    )
    assert reply.body.get("clientToken") == "cmd-42"


# -- null handling ------------------------------------------------------------------


def test_null_deletes_a_key(shadows: Shadows, thing: str) -> None:
    shadows.update(thing, body({"state": {"reported": {"zone": "A", "cargo": True}}}))
    shadows.update(thing, body({"state": {"reported": {"cargo": None}}}))
    assert shadows.get(thing).body["state"]["reported"] == {"zone": "A"}


def test_desired_null_clears_the_whole_desired_section(
    request: pytest.FixtureRequest, shadows: Shadows, thing: str
) -> None:
    moto_gap(request, shadows, '{"desired": null} does not clear')
    shadows.update(
        thing, body({"state": {"reported": {"zone": "A"}, "desired": {"zone": "B", "x": 1}}})
    )
    shadows.update(thing, body({"state": {"desired": None}}))
    state = shadows.get(thing).body["state"]
    assert "desired" not in state
    assert "delta" not in state
    assert state["reported"] == {"zone": "A"}


# -- metadata -------------------------------------------------------------------------


def test_metadata_changes_only_for_keys_an_update_touches(
    request: pytest.FixtureRequest, shadows: Shadows, thing: str
) -> None:
    moto_gap(request, shadows, "metadata timestamps are re-stamped for every key")
    shadows.update(thing, body({"state": {"reported": {"zone": "A", "cargo": False}}}))
    before = shadows.get(thing).body["metadata"]["reported"]
    # Timestamps are whole seconds, as AWS's are: the next update comes in a later second.
    stamped = before["cargo"]["timestamp"]
    wait_until(lambda: time.time() >= stamped + 1, 2)
    shadows.update(thing, body({"state": {"reported": {"cargo": True}}}))
    after = shadows.get(thing).body["metadata"]["reported"]
    assert after["zone"] == before["zone"]
    assert after["cargo"]["timestamp"] > before["cargo"]["timestamp"]


# -- errors and limits ----------------------------------------------------------------


@pytest.mark.parametrize(
    ("payload", "message"),
    [
        (b"{not json", "Invalid JSON"),
        (b'{"clientToken": "x"}', "Missing required node: state"),
        (b'{"state": 5}', "State node must be an object"),
        (b'{"state": {"desired": [1]}}', "Desired node must be an object"),
        (b'{"state": {"reported": "idle"}}', "Reported node must be an object"),
        (b'{"state": {"delta": {"a": 1}}}', "State contains an invalid node"),
        (b'{"state": {"reported": {"a": 1}}, "version": "2"}', "Invalid version"),
    ],
    ids=["json", "state", "state-type", "desired-type", "reported-type", "node", "version"],
)
def test_malformed_requests_are_rejected_with_400(
    request: pytest.FixtureRequest, shadows: Shadows, thing: str, payload: bytes, message: str
) -> None:
    if message in (
        "Desired node must be an object",
        "Reported node must be an object",
        "Invalid version",
    ):
        moto_gap(request, shadows, f"accepts what AWS rejects with '{message}'")
    reply = shadows.update(thing, payload)
    assert reply.status == 400
    assert reply.error == "InvalidRequestException"
    if shadows.kind != "moto":
        assert reply.body["message"] == message


def test_nesting_deeper_than_six_levels_is_rejected(
    request: pytest.FixtureRequest, shadows: Shadows, thing: str
) -> None:
    moto_gap(request, shadows, "no depth limit")
    six = {"l1": {"l2": {"l3": {"l4": {"l5": {"l6": 1}}}}}}
    seven = {"l1": {"l2": {"l3": {"l4": {"l5": {"l6": {"l7": 1}}}}}}}
    assert shadows.update(thing, body({"state": {"reported": six}})).status == 200
    reply = shadows.update(thing, body({"state": {"reported": seven}}))
    assert reply.status == 400
    assert reply.body["message"] == "JSON contains too many levels of nesting; maximum is 6"


def test_a_document_over_8_kb_is_rejected_with_413(
    request: pytest.FixtureRequest, shadows: Shadows, thing: str
) -> None:
    moto_gap(request, shadows, "no size limit")
    reply = shadows.update(thing, body({"state": {"reported": {"blob": "x" * 8200}}}))
    assert reply.status == 413
    assert reply.error == "RequestEntityTooLargeException"
    assert shadows.get(thing).status == 404


def test_a_client_token_over_64_bytes_is_rejected(
    request: pytest.FixtureRequest, shadows: Shadows, thing: str
) -> None:
    moto_gap(request, shadows, "clientToken length is not checked")
    reply = shadows.update(thing, body({"state": {"reported": {}}, "clientToken": "t" * 65}))
    assert reply.status == 400
    assert reply.body["message"] == "Invalid clientToken"


# -- delete and named shadows ---------------------------------------------------------


def test_delete_then_recreate_keeps_counting_versions(shadows: Shadows, thing: str) -> None:
    shadows.update(thing, body({"state": {"reported": {"zone": "A"}}}))
    shadows.update(thing, body({"state": {"reported": {"zone": "B"}}}))
    deleted = shadows.delete(thing)
    assert deleted.status == 200
    assert shadows.get(thing).status == 404
    again = shadows.update(thing, body({"state": {"reported": {"zone": "C"}}}))
    assert again.body["version"] > 2
    assert shadows.get(thing).body["state"] == {"reported": {"zone": "C"}}


def test_deleting_a_missing_shadow_is_404(
    request: pytest.FixtureRequest, shadows: Shadows, thing: str
) -> None:
    moto_gap(request, shadows, "deleting an already deleted shadow succeeds")
    shadows.update(thing, body({"state": {"reported": {"zone": "A"}}}))
    assert shadows.delete(thing).status == 200
    reply = shadows.delete(thing)
    assert reply.status == 404
    assert reply.error == "ResourceNotFoundException"


def test_named_shadows_are_separate_documents(shadows: Shadows, thing: str) -> None:
    shadows.update(thing, body({"state": {"reported": {"zone": "A"}}}))
    shadows.update(thing, body({"state": {"reported": {"battery": 80}}}), name="power")
    assert shadows.get(thing, name="power").body["state"]["reported"] == {"battery": 80}
    assert shadows.get(thing).body["state"]["reported"] == {"zone": "A"}
    assert shadows.get(thing, name="other").status == 404


def test_list_named_shadows(request: pytest.FixtureRequest, shadows: Shadows, thing: str) -> None:
    if shadows.kind == "mqtt":
        pytest.skip("the shadow MQTT API has no list operation (AWS has none either)")
    moto_gap(request, shadows, "a deleted named shadow stays listed")
    for name in ("power", "arm", "tray"):
        shadows.update(thing, body({"state": {"reported": {"ok": True}}}), name=name)
    shadows.delete(thing, name="tray")
    assert shadows.list_named(thing) == ["arm", "power"]


# -- what MQTT subscribers see --------------------------------------------------------


def test_delta_and_documents_are_published(local_stack: LocalStack, aws_credentials: None) -> None:
    with MqttClient(local_stack.service_endpoint()) as client:
        mqtt = MqttShadows(client)
        thing = unique_thing()
        mqtt.prepare(thing)
        mqtt.update(thing, body({"state": {"reported": {"zone": "A"}}}))
        # When the desired zone is set through the data plane (as the skill could)
        http = boto3.client("iot-data", endpoint_url=local_stack.api_url)
        http.update_thing_shadow(
            thingName=thing,
            payload=body({"state": {"desired": {"zone": "B"}}, "clientToken": "c1"}),
        )
        # Then the robot's delta topic carries only the difference, with the token
        delta = mqtt.drain(thing, topics.shadow(thing, "update/delta"))
        assert delta["state"] == {"zone": "B"}
        assert delta["version"] == 2
        assert delta["clientToken"] == "c1"
        assert set(delta["metadata"]) == {"zone"}
        # And update/documents carries the previous and current documents
        documents = mqtt.drain(thing, topics.shadow(thing, "update/documents"))
        assert documents["previous"]["version"] == 1
        assert documents["previous"]["state"] == {"reported": {"zone": "A"}}
        assert documents["current"]["state"] == {
            "reported": {"zone": "A"},
            "desired": {"zone": "B"},
        }
        assert documents["current"]["version"] == 2


def test_a_rejection_carries_the_client_token(local_stack: LocalStack) -> None:
    with MqttClient(local_stack.service_endpoint()) as client:
        mqtt = MqttShadows(client)
        thing = unique_thing()
        mqtt.prepare(thing)
        reply = mqtt.update(thing, body({"state": 1, "clientToken": "c9"}))
        assert reply.status == 400
        assert reply.body["clientToken"] == "c9"
        assert isinstance(reply.body["timestamp"], int)
