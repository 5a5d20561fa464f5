"""Input generators shared by the fuzz tests: raw bytes, any JSON, and documents that are
almost valid (one field wrong at a time), which is where decoders break."""

from __future__ import annotations

import json
from typing import Any

from hypothesis import strategies as st

from vahr.protocol import ACTIONS

# Text a person or a broken client could send: any Unicode, but also the characters that
# matter to topics, URLs, YAML, CSV and SSML.
SPECIAL = st.sampled_from(
    ["", " ", "/", "+", "#", "$", "%", "%2F", "..", "\x00", "\n", "'", '"', ",", ":", "<", "&"]
)
text = st.one_of(st.text(max_size=40), SPECIAL, st.text(alphabet="ab/+#$%.-_ ", max_size=12))
scalars = st.one_of(
    st.none(),
    st.booleans(),
    st.integers(min_value=-(2**70), max_value=2**70),
    st.floats(allow_nan=False, allow_infinity=False),
    text,
)


def json_values(max_leaves: int = 12) -> st.SearchStrategy[Any]:
    """Any JSON value (nested lists and objects of scalars)."""
    return st.recursive(
        scalars,
        lambda inner: st.one_of(
            st.lists(inner, max_size=4), st.dictionaries(text, inner, max_size=4)
        ),
        max_leaves=max_leaves,
    )


def deep_arrays(depth: int) -> bytes:
    """JSON nested deeper than parsers recurse (8 KB holds about 4,000 levels)."""
    return b"[" * depth + b"]" * depth


def deeply_nested(depth: int) -> Any:
    value: Any = 1
    for _ in range(depth):
        value = {"n": value}
    return value


def paths_in(value: Any, prefix: tuple[Any, ...] = ()) -> list[tuple[Any, ...]]:
    """Every key path inside a JSON document (for mutating one place of a valid one)."""
    found = [prefix] if prefix else []
    if isinstance(value, dict):
        for key, inner in value.items():
            found += paths_in(inner, (*prefix, key))
    elif isinstance(value, list):
        for index, inner in enumerate(value):
            found += paths_in(inner, (*prefix, index))
    return found


def encode(value: Any) -> bytes:
    return json.dumps(value, ensure_ascii=False).encode("utf-8", "surrogatepass")


ZONES = ["A", "B", "C", "D", "LOADING"]
THINGS = ["placebot1", "placebot2"]


@st.composite
def commands(draw: st.DrawFn) -> dict[str, Any]:
    """A command message, valid or with one or more fields broken."""
    action = draw(st.one_of(st.sampled_from(ACTIONS), text))
    params: Any = {}
    if action in ("navigate", "deliver"):
        params = {"zone": draw(st.one_of(st.sampled_from(ZONES), text))}
    elif action == "sequential_delivery":
        params = {
            "zone": draw(st.sampled_from(ZONES)),
            "after": draw(st.one_of(st.none(), st.sampled_from(THINGS), text)),
        }
    body: dict[str, Any] = {
        "id": draw(st.one_of(st.uuids().map(lambda u: u.hex), text)),
        "action": action,
        "params": params,
        "issued_at": draw(
            st.one_of(
                st.just("2026-11-22T10:00:00Z"),
                st.datetimes().map(lambda d: d.isoformat()),
                text,
            )
        ),
        "source": draw(st.sampled_from(["alexa", "console", "robot:placebot2", "Console", ""])),
    }
    for _ in range(draw(st.integers(0, 2))):
        key = draw(st.sampled_from([*body, "params.zone", "extra"]))
        if key == "params.zone" and isinstance(body.get("params"), dict):
            body["params"]["zone"] = draw(scalars)
        elif draw(st.booleans()):
            body.pop(key, None)
        else:
            body[key] = draw(json_values(4))
    return body


def command_payloads() -> st.SearchStrategy[bytes]:
    return st.one_of(
        commands().map(encode),
        json_values().map(encode),
        st.binary(max_size=64),
        st.integers(8 * 1024 - 64, 8 * 1024 + 64).map(lambda n: b'{"id":"' + b"x" * n + b'"}'),
        st.integers(10, 200).map(lambda d: encode(deeply_nested(d))),
        st.integers(900, 4000).map(
            lambda d: b'{"id":"deep","action":"ping","params":' + deep_arrays(d) + b"}"
        ),
        st.integers(900, 4000).map(deep_arrays),
    )


@st.composite
def shadow_requests(draw: st.DrawFn) -> dict[str, Any]:
    """A shadow update request, valid or broken."""
    state: Any = {}
    for section in draw(st.sets(st.sampled_from(["desired", "reported", "delta", "x"]))):
        state[section] = draw(st.one_of(st.none(), json_values(), st.just({"zone": "A"})))
    body: dict[str, Any] = {"state": state}
    if draw(st.booleans()):
        body["clientToken"] = draw(st.one_of(text, st.integers(), st.text(min_size=60)))
    if draw(st.booleans()):
        body["version"] = draw(st.one_of(st.integers(-2, 5), st.booleans(), text))
    if draw(st.integers(0, 4)) == 0:
        body.pop("state")
        body["state"] = draw(json_values(3))
    return body


def shadow_payloads() -> st.SearchStrategy[bytes]:
    return st.one_of(
        shadow_requests().map(encode),
        json_values().map(encode),
        st.binary(max_size=64),
        st.integers(3, 12).map(lambda d: encode({"state": {"reported": deeply_nested(d)}})),
        st.integers(900, 4000).map(
            lambda d: b'{"state":{"reported":{"a":' + deep_arrays(d) + b"}}}"
        ),
        st.integers(7 * 1024, 9 * 1024).map(
            lambda n: encode({"state": {"reported": {"blob": "x" * n}}})
        ),
    )
