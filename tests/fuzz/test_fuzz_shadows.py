"""Fuzz: shadow documents and deltas, into the shadow store directly and into the shadow
service over a real mosquitto.

Properties: every request is accepted or rejected with one of AWS's codes and a message;
a rejected request leaves the stored document exactly as it was; an accepted update bumps
the version by one, keeps the stored state within AWS's limits, and publishes a delta
equal to the desired keys that differ from reported; the service answers every request
once and keeps serving.
"""

from __future__ import annotations

import json
import threading
from typing import TYPE_CHECKING, Any

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from tests.fuzz.strategies import shadow_payloads
from tests.fuzz.tally import TALLY, budget
from vahr.plumbing.mqtt import MqttClient
from vahr.twin.shadow_store import (
    MAX_STATE_BYTES,
    ShadowError,
    ShadowStore,
    delta_of,
)

if TYPE_CHECKING:
    from collections.abc import Iterator

    from vahr.twin.stack import LocalStack

AWS_CODES = {400, 404, 409, 413, 415}
NAMES = st.sampled_from([None, "arm", "named-1"])
OPERATIONS = st.sampled_from(["update", "update", "update", "get", "delete"])


def _stored(store: ShadowStore, thing: str, name: str | None) -> dict[str, Any] | None:
    try:
        document = store.get(thing, name)
    except ShadowError:
        return None
    document.pop("timestamp")
    return document


@given(requests=st.lists(st.tuples(OPERATIONS, NAMES, shadow_payloads()), min_size=1, max_size=6))
@settings(max_examples=budget(300))
def test_the_store_accepts_or_rejects_and_a_rejection_changes_nothing(
    requests: list[tuple[str, str | None, bytes]],
) -> None:
    store = ShadowStore(None, clock=lambda: 1_700_000_000.0)
    for operation, name, payload in requests:
        before = _stored(store, "fuzzbot", name)
        try:
            if operation == "update":
                result = store.update("fuzzbot", name, payload)
            elif operation == "get":
                store.get("fuzzbot", name, payload)
                TALLY.accepted("shadow store")
                continue
            else:
                store.delete("fuzzbot", name, payload)
                TALLY.accepted("shadow store")
                continue
        except ShadowError as err:
            assert err.code in AWS_CODES and err.message, err
            assert _stored(store, "fuzzbot", name) == before
            TALLY.rejected("shadow store", str(err.code))
            continue
        after = _stored(store, "fuzzbot", name)
        assert after is not None
        if before is not None:
            assert after["version"] == before["version"] + 1
        assert result.accepted["version"] == after["version"]
        assert len(json.dumps(after["state"], separators=(",", ":"))) <= MAX_STATE_BYTES * 2
        desired = after["state"].get("desired", {})
        expected_delta = delta_of(desired, after["state"].get("reported", {}))
        if result.delta is not None:
            assert result.delta["state"] == expected_delta and expected_delta
        TALLY.accepted("shadow store")


# -- the shadow service over MQTT ----------------------------------------------------------


class Answers:
    """Every answer the shadow service publishes for `fuzzbot`, in order."""

    def __init__(self) -> None:
        self.messages: list[tuple[str, dict[str, Any]]] = []
        self._changed = threading.Condition()

    def on_message(self, topic: str, payload: bytes) -> None:
        with self._changed:
            self.messages.append((topic, json.loads(payload)))
            self._changed.notify_all()

    def wait_answer(self, after: int, operation: str, timeout_s: float = 10.0) -> tuple[str, Any]:
        def answer() -> tuple[str, Any] | None:
            for topic, body in self.messages[after:]:
                if topic.endswith((f"{operation}/accepted", f"{operation}/rejected")):
                    return topic, body
            return None

        with self._changed:
            if not self._changed.wait_for(lambda: answer() is not None, timeout_s):
                raise TimeoutError(f"no answer to {operation}")
            found = answer()
            assert found is not None
            return found


@pytest.fixture(scope="module")
def service(
    tmp_path_factory: pytest.TempPathFactory,
) -> Iterator[tuple[LocalStack, MqttClient, Answers]]:
    from vahr.plumbing.ports import free_port
    from vahr.twin.stack import LocalStack, StackConfig

    config = StackConfig(
        state_dir=tmp_path_factory.mktemp("fuzz-shadow"),
        mqtts_port=free_port(),
        mqtt_port=None,
        api_port=free_port(),
    )
    with LocalStack(config) as stack, MqttClient(stack.service_endpoint()) as client:
        answers = Answers()
        client.subscribe("$aws/things/fuzzbot/shadow/#", answers.on_message)
        yield stack, client, answers


@given(operation=OPERATIONS, name=NAMES, payload=shadow_payloads())
@settings(max_examples=budget(60))
def test_the_service_answers_every_request_once_and_keeps_serving(
    service: tuple[LocalStack, MqttClient, Answers],
    operation: str,
    name: str | None,
    payload: bytes,
) -> None:
    stack, client, answers = service
    assert stack.store is not None
    before = _stored(stack.store, "fuzzbot", name)
    prefix = "$aws/things/fuzzbot/shadow" + (f"/name/{name}" if name else "")
    mark = len(answers.messages)
    # When a request arrives over MQTT
    client.publish(f"{prefix}/{operation}", payload)
    # Then exactly one answer comes back on AWS's topics
    topic, body = answers.wait_answer(mark, operation)
    assert topic.startswith(prefix + "/")
    if topic.endswith("/rejected"):
        assert body["code"] in AWS_CODES and body["message"], body
        assert _stored(stack.store, "fuzzbot", name) == before
        TALLY.rejected("shadow service over MQTT", str(body["code"]))
    else:
        TALLY.accepted("shadow service over MQTT")
    # And the service still serves a plain get
    mark = len(answers.messages)
    client.publish("$aws/things/fuzzbot/shadow/get", b"")
    answers.wait_answer(mark, "get")
