"""The shadow document logic without any transport: persistence and AWS's rules."""

from __future__ import annotations

import json
from typing import TYPE_CHECKING

import pytest

from vahr.twin.shadow_store import ShadowError, ShadowStore, delta_of

if TYPE_CHECKING:
    from pathlib import Path


def test_shadows_survive_a_restart(tmp_path: Path) -> None:
    # Given a shadow written by one store
    first = ShadowStore(tmp_path / "shadows.sqlite3")
    first.update("placebot1", None, b'{"state":{"reported":{"zone":"A"}}}')
    first.update("placebot1", "power", b'{"state":{"reported":{"battery":80}}}')
    first.close()
    # When the service starts again on the same file
    second = ShadowStore(tmp_path / "shadows.sqlite3")
    # Then the documents, versions and named shadows are still there
    assert second.get("placebot1")["state"] == {"reported": {"zone": "A"}}
    assert second.list_named("placebot1") == ["power"]
    result = second.update("placebot1", None, b'{"state":{"reported":{"zone":"B"}}}')
    assert result.accepted["version"] == 2
    second.close()


def test_timestamps_come_from_the_injected_clock() -> None:
    now = [1000.0]
    store = ShadowStore(clock=lambda: now[0])
    store.update("t", None, b'{"state":{"reported":{"a":1,"b":1}}}')
    now[0] = 1005.0
    store.update("t", None, b'{"state":{"reported":{"b":2}}}')
    metadata = store.get("t")["metadata"]["reported"]
    assert metadata == {"a": {"timestamp": 1000}, "b": {"timestamp": 1005}}


def test_a_stale_version_names_the_client_token() -> None:
    store = ShadowStore()
    store.update("t", None, b'{"state":{"reported":{"a":1}}}')
    with pytest.raises(ShadowError) as caught:
        store.update("t", None, b'{"state":{"reported":{"a":2}},"version":7,"clientToken":"c"}')
    assert (caught.value.code, caught.value.message) == (409, "Version conflict")
    assert caught.value.payload(5) == {
        "code": 409,
        "message": "Version conflict",
        "timestamp": 5,
        "clientToken": "c",
    }


def test_non_utf8_is_415() -> None:
    with pytest.raises(ShadowError) as caught:
        ShadowStore().update("t", None, b'{"state":{"reported":{"a":"\xff"}}}')
    assert caught.value.code == 415


def test_arrays_are_replaced_whole_and_compared_as_values() -> None:
    store = ShadowStore()
    store.update("t", None, json.dumps({"state": {"reported": {"path": [1, 2, 3]}}}).encode())
    store.update("t", None, json.dumps({"state": {"reported": {"path": [4]}}}).encode())
    assert store.get("t")["state"]["reported"] == {"path": [4]}
    assert delta_of({"path": [4], "x": {"y": 1}}, {"path": [4], "x": {"y": 2}}) == {"x": {"y": 1}}


def test_deleting_every_desired_key_removes_the_section() -> None:
    store = ShadowStore()
    store.update("t", None, b'{"state":{"desired":{"zone":"B"},"reported":{"zone":"A"}}}')
    store.update("t", None, b'{"state":{"desired":{"zone":null}}}')
    assert store.get("t")["state"] == {"reported": {"zone": "A"}}
