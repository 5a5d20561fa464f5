"""Fuzz: the operator station's endpoints (`vahr station`), over a real socket.

The station's server runs with its real API, feed, panel controls and experiment desk; the
wire they publish to is recorded, and the assistant is a recording stand-in (what it is
asked is the property; what the Alexa simulator makes of a request is fuzzed elsewhere).
Push-to-talk parses the uploaded clip for real; its recognizer hears nothing (recognition
of real audio is tested in tests/integration/station).

Properties: every request gets a well-formed HTTP answer, never a 5xx and never a dropped
connection; every error is a JSON `{"error": one line}`; a rejected request publishes
nothing, asks the assistant nothing and leaves the page's snapshot as it was; an accepted
order publishes exactly one valid command; the station still answers its health check.
"""

from __future__ import annotations

import http.client
import json
import socket
import struct
from typing import TYPE_CHECKING, Any

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from tests.fuzz.strategies import THINGS, ZONES, encode, json_values, text
from tests.fuzz.tally import TALLY, budget
from tests.support.station_stand_ins import RecordingAssistant, Wire
from vahr.plumbing.ports import free_port
from vahr.protocol import decode_command
from vahr.speech.stt import NOTHING_HEARD
from vahr.station.app import StationApp
from vahr.station.controls import Controls
from vahr.station.desk import Desk
from vahr.station.feed import Feed
from vahr.station.server import StationServer
from vahr.station.voice import PushToTalk

if TYPE_CHECKING:
    from collections.abc import Iterator

    from vahr.domain import Fleet
    from vahr.speech.audio import Audio
    from vahr.speech.stt import Recognition

BOUNDARY = "station endpoints"
JSON_ROUTES = ["/api/command", "/api/stop", "/api/say", "/api/speech", "/api/interaction",
               "/api/puzzle"]  # fmt: skip
PATHS = st.one_of(
    st.sampled_from(
        [
            *JSON_ROUTES,
            "/api/voice",
            "/api/health",
            "/api/snapshot",
            "/",
            "/index.html",
            "/static/station.js",
            "/static/../server.py",
            "/static/%2e%2e/app.py",
            "/favicon.ico",
            "/api/stream?x=1",
            "//api/health",
            "/api/command?robot=placebot1",
            "/%00",
            "*",
        ]
    ),  # fmt: skip
    text.map(lambda t: "/" + t.replace(" ", "%20").replace("\n", "")),
)
METHODS = st.sampled_from(["GET", "POST", "PUT", "DELETE", "HEAD", "OPTIONS", "PATCH", "BREW"])
CONTENT_TYPES = st.sampled_from(
    ["application/json", "audio/wav", "text/plain", "application/json; charset=utf-8",
     "multipart/form-data", ""]
)  # fmt: skip
ORIGINS = st.sampled_from([None, None, "http://evil.example", "null", "http://127.0.0.1"])


@st.composite
def orders(draw: st.DrawFn) -> dict[str, Any]:
    """A body for one of the JSON routes: well formed, or with fields broken or missing."""
    body: dict[str, Any] = {}
    for field, good in (
        ("robot", st.sampled_from([*THINGS, "placebot9", ""])),
        ("action", st.sampled_from(["navigate", "stop", "deliver", ""])),
        ("zone", st.sampled_from([*ZONES, "Q", "a", ""])),
        ("utterance", st.sampled_from(["where are the robots", "", " ", "x" * 301])),
        ("origin", st.sampled_from(["station", "station-weather", "station-voice", "alexa"])),
        ("text", st.sampled_from(["hello", "", "y" * 1001])),
        ("kind", st.sampled_from(["click", "key", "zone"])),
    ):
        choice = draw(st.sampled_from(["good", "absent", "absent", "any"]))
        if choice == "good":
            body[field] = draw(good)
        elif choice == "any":
            body[field] = draw(json_values(4))
    body.update(draw(st.dictionaries(text, json_values(4), max_size=2)))
    return body


def wav(rate: int, channels: int, width: int, frames: bytes) -> bytes:
    """A RIFF/WAVE file with the given header fields (any of them may be wrong)."""
    fmt = struct.pack("<HHIIHH", 1, channels, rate, rate * channels * width, channels * width,
                      8 * width)  # fmt: skip
    chunks = b"fmt " + struct.pack("<I", len(fmt)) + fmt
    chunks += b"data" + struct.pack("<I", len(frames)) + frames
    return b"RIFF" + struct.pack("<I", 4 + len(chunks)) + b"WAVE" + chunks


CLIPS = st.one_of(
    st.binary(max_size=300),
    st.builds(
        wav,
        st.sampled_from([16_000, 16_000, 8_000, 44_100, 0]),
        st.sampled_from([1, 1, 2, 0]),
        st.sampled_from([2, 2, 1, 4]),
        st.binary(max_size=2_000),
    ),
    st.builds(
        lambda head, tail: head[: len(head) // 2] + tail,
        st.builds(wav, st.just(16_000), st.just(1), st.just(2), st.binary(max_size=400)),
        st.binary(max_size=40),
    ),  # fmt: skip
)


class HearsNothing:
    def recognize(self, audio: Audio) -> Recognition:
        return NOTHING_HEARD


class Station:
    def __init__(self, fleet: Fleet) -> None:
        self.wire, self.assistant = Wire(), RecordingAssistant()
        self.feed = Feed(fleet)
        desk = Desk(self.feed, self.wire.publish)
        app = StationApp(
            feed=self.feed,
            controls=Controls(fleet, desk, self.wire.publish),
            desk=desk,
            assistant=self.assistant,
            push_to_talk=PushToTalk(self.assistant, HearsNothing),
            synthesize=lambda text: wav(16_000, 1, 2, b"\0\0" * 160),
        )
        self.server = StationServer(app, port=free_port())


@pytest.fixture(scope="module")
def station(fleet: Fleet) -> Iterator[Station]:
    running = Station(fleet)
    with running.server:
        yield running


def exchange(port: int, method: str, path: str, headers: dict[str, str], body: bytes
             ) -> tuple[int, str, bytes]:  # fmt: skip
    lines = [f"{method} {path} HTTP/1.1", f"Host: 127.0.0.1:{port}", "Connection: close"]
    lines += [f"{name}: {value}" for name, value in headers.items()]
    lines.append(f"Content-Length: {len(body)}")
    raw = ("\r\n".join(lines) + "\r\n\r\n").encode("latin-1", "replace") + body
    with socket.create_connection(("127.0.0.1", port), timeout=10) as sock:
        sock.sendall(raw)
        response = http.client.HTTPResponse(sock, method=method)
        response.begin()
        # A stream (GET /api/stream) never ends: its first bytes are enough.
        streaming = response.getheader("Content-Type", "") == "text/event-stream"
        answer = response.read(16) if streaming else (response.read() if method != "HEAD" else b"")
        return response.status, response.getheader("Content-Type", ""), answer


def page_state(station: Station) -> dict[str, Any]:
    """What a page would start from, less the clock."""
    snapshot = station.feed.snapshot()
    snapshot.pop("server_time")
    return snapshot


def check(station: Station, method: str, path: str, headers: dict[str, str], body: bytes) -> None:
    sent, asked = len(station.wire.sent), len(station.assistant.asked)
    before = page_state(station)
    status, kind, answer = exchange(station.server.port, method, path, headers, body)
    assert status < 500, (status, answer[:300])
    if status >= 400:
        if method != "HEAD":
            assert kind == "application/json", kind
            error = json.loads(answer)["error"]
            assert error and "\n" not in error, error
        assert len(station.wire.sent) == sent
        assert len(station.assistant.asked) == asked
        assert page_state(station) == before
        TALLY.rejected(BOUNDARY, str(status))
    else:
        for _, payload in station.wire.sent[sent:]:
            if path in ("/api/command", "/api/stop"):
                decode_command(payload)  # an accepted order is a valid command
        assert len(station.wire.sent) - sent <= 1
        TALLY.accepted(BOUNDARY)
    assert exchange(station.server.port, "GET", "/api/health", {}, b"")[0] == 200


@given(
    method=METHODS,
    path=PATHS,
    kind=CONTENT_TYPES,
    origin=ORIGINS,
    body=st.one_of(orders().map(encode), json_values().map(encode), st.binary(max_size=200)),
)
@settings(max_examples=budget(150))
def test_every_request_gets_a_clear_answer_and_rejections_change_nothing(
    station: Station, method: str, path: str, kind: str, origin: str | None, body: bytes
) -> None:
    headers = {"Content-Type": kind} if kind else {}
    if origin:
        headers["Origin"] = origin
    check(station, method, path, headers, body)


@given(route=st.sampled_from(JSON_ROUTES), body=orders())
@settings(max_examples=budget(150))
def test_orders_of_every_shape_are_judged_by_their_fields(
    station: Station, route: str, body: dict[str, Any]
) -> None:
    check(station, "POST", route, {"Content-Type": "application/json"}, encode(body))


@given(clip=CLIPS)
@settings(max_examples=budget(100))
def test_push_to_talk_takes_any_upload(station: Station, clip: bytes) -> None:
    check(station, "POST", "/api/voice", {"Content-Type": "audio/wav"}, clip)
