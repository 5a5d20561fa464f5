"""Fuzz: the data-plane HTTP API (what boto3's iot-data client talks to), with raw HTTP.

Properties: every request gets a well-formed HTTP answer (never a dropped connection,
never a 5xx); every error is a JSON body `{"code", "message"}` with the status as its code
and an `x-amzn-ErrorType` header; a rejected request publishes nothing and changes no
shadow; the server answers a health check afterwards.
"""

from __future__ import annotations

import http.client
import json
import socket
import sqlite3
from typing import TYPE_CHECKING, Any
from urllib.parse import quote

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from tests.fuzz.strategies import command_payloads, shadow_payloads, text
from tests.fuzz.tally import TALLY, budget
from vahr.local.alexa_host import serve_alexa

if TYPE_CHECKING:
    from collections.abc import Iterator

    from vahr.twin.stack import LocalStack

SEGMENTS = st.one_of(
    st.sampled_from(
        [
            "topics",
            "things",
            "shadow",
            "api",
            "ListNamedShadowsForThing",
            "vahr",
            "health",
            "meter",
            "reset",
            "say",
            "status",
            "dashboard",
            "placebot1",
            "fuzzbot",
            "..",
            ".",
            "%2F",
            "%00",
            "%",
            "+",
            "#",
            "$aws",
            "vahr%2Frobots%2Ffuzzbot%2Fcmd",
            "",
        ]
    ),  # fmt: skip
    text.map(lambda t: quote(t, safe="")),
    text.map(lambda t: quote(t, safe="/%+$#")),
)
ROUTES = st.sampled_from(
    ["/topics/vahr/robots/fuzzbot/cmd", "/things/fuzzbot/shadow",
     "/api/things/shadow/ListNamedShadowsForThing/fuzzbot", "/vahr/say", "/vahr/health",
     "/topics/%24aws/things/fuzzbot/shadow/update"]
)  # fmt: skip
QUERY_KEYS = st.one_of(st.sampled_from(["qos", "retain", "name", "pageSize", "nextToken"]), text)
QUERY_VALUES = st.one_of(
    st.sampled_from(["0", "1", "2", "-1", "true", "TRUE", "", "x", "9" * 30, "arm"]), text
)


@st.composite
def targets(draw: st.DrawFn) -> str:
    if draw(st.booleans()):
        path = draw(ROUTES)
    else:
        path = "/" + "/".join(draw(st.lists(SEGMENTS, max_size=6)))
    pairs = draw(st.lists(st.tuples(QUERY_KEYS, QUERY_VALUES), max_size=3))
    if pairs:
        raw = draw(st.booleans())
        path += "?" + "&".join(
            f"{k}={v}" if raw else f"{quote(k, safe='')}={quote(v, safe='')}" for k, v in pairs
        )
    return path


METHODS = st.one_of(
    st.sampled_from(["GET", "POST", "DELETE", "PUT", "PATCH", "HEAD", "OPTIONS"]),
    st.text(alphabet="ABCDEFGHIJKLMNOPQRSTUVWXYZ_", min_size=1, max_size=10),
)
HEADER_NAMES = st.one_of(
    st.sampled_from(["Content-Type", "Authorization", "X-Amz-Date", "Accept", "Expect"]),
    st.text(alphabet="abcdefghijklmnopqrstuvwxyz-", min_size=1, max_size=20),
)
HEADER_VALUES = st.text(alphabet=st.characters(min_codepoint=0x20, max_codepoint=0x7E), max_size=60)
BODIES = st.one_of(st.just(b""), command_payloads(), shadow_payloads(), st.binary(max_size=200))
# How the body's length is declared: honestly, not at all, or wrongly (never longer than
# the body: a server must wait for a body it was promised).
LENGTHS = st.sampled_from(["exact", "exact", "missing", "shorter", "spaced", "abc", "-1", "+5"])


def _request(port: int, method: str, target: str, headers: list[tuple[str, str]],
             body: bytes, length: str, *, signed: bool = False) -> http.client.HTTPResponse:  # fmt: skip
    declared = {
        "exact": str(len(body)), "missing": None, "shorter": str(len(body) // 2),
        "spaced": f" {len(body)} ",
    }.get(length, length)  # fmt: skip
    lines = [f"{method} {target} HTTP/1.1", "Host: 127.0.0.1", "Connection: close"]
    if signed:
        # As boto3 signs (the data plane serves writes only to signed or JSON requests).
        lines.append("Authorization: AWS4-HMAC-SHA256 Credential=fuzz/20260101/us-east-1/iotdata")
    lines += [f"{name}: {value}" for name, value in headers if name.lower() != "content-length"]
    if declared is not None:
        lines.append(f"Content-Length: {declared}")
    raw = ("\r\n".join(lines) + "\r\n\r\n").encode("latin-1", "replace") + body
    sock = socket.create_connection(("127.0.0.1", port), timeout=10)
    sock.sendall(raw)
    response = http.client.HTTPResponse(sock, method=method)
    try:
        response.begin()
    finally:
        sock.close()
    return response


@pytest.fixture(scope="module")
def api(tmp_path_factory: pytest.TempPathFactory) -> Iterator[tuple[LocalStack, list[str]]]:
    from vahr.plumbing.ports import free_port
    from vahr.twin.stack import LocalStack, StackConfig

    config = StackConfig(
        state_dir=tmp_path_factory.mktemp("fuzz-api"),
        mqtts_port=free_port(),
        mqtt_port=None,
        api_port=free_port(),
    )
    with LocalStack(config) as stack:
        serve_alexa(stack, ack_timeout_s=0.05)
        published: list[str] = []
        assert stack.dataplane is not None
        stack.dataplane.publish_observers.append(lambda topic, _: published.append(topic))
        yield stack, published


def _shadows(stack: LocalStack) -> list[Any]:
    with sqlite3.connect(stack.database) as db:
        return db.execute("SELECT * FROM shadows ORDER BY thing, name").fetchall()


@given(
    method=METHODS,
    target=targets(),
    headers=st.lists(st.tuples(HEADER_NAMES, HEADER_VALUES), max_size=4),
    body=BODIES,
    length=LENGTHS,
    signed=st.booleans(),
)
@settings(max_examples=budget(150))
def test_every_request_gets_a_clear_answer_and_rejections_change_nothing(
    api: tuple[LocalStack, list[str]],
    method: str,
    target: str,
    headers: list[tuple[str, str]],
    body: bytes,
    length: str,
    signed: bool,
) -> None:
    stack, published = api
    before, sent = _shadows(stack), len(published)
    response = _request(stack.config.api_port, method, target, headers, body, length, signed=signed)
    answer = response.read() if method != "HEAD" else b""
    assert response.status < 500, (response.status, answer[:300])
    if response.status >= 400:
        if method != "HEAD":
            error = json.loads(answer)
            assert error["code"] == response.status and error["message"], error
        assert response.getheader("x-amzn-ErrorType"), response.getheaders()
        assert _shadows(stack) == before
        assert len(published) == sent
        TALLY.rejected("data-plane HTTP API", str(response.status))
    else:
        TALLY.accepted("data-plane HTTP API")
    health = _request(stack.config.api_port, "GET", "/vahr/health", [], b"", "missing")
    assert health.status == 200
