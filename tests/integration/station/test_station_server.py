"""The station's HTTP server over a real socket: its files, the event stream, and its
security stance (the host it answers to, origins, content types, sizes, the token)."""

from __future__ import annotations

import http.client
import json
import socket
from typing import TYPE_CHECKING, Any

import pytest

from vahr.plumbing.ports import free_port
from vahr.station.app import StationApp
from vahr.station.controls import Controls
from vahr.station.desk import Desk
from vahr.station.feed import Feed
from vahr.station.server import MAX_AUDIO_BYTES, MAX_JSON_BYTES, StationServer

if TYPE_CHECKING:
    from collections.abc import Iterator

    from vahr.domain import Fleet

TOKEN = "a-token-of-twenty-characters"


def make_app(fleet: Fleet) -> StationApp:
    feed = Feed(fleet)
    desk = Desk(feed, lambda topic, payload: None)
    return StationApp(
        feed=feed,
        controls=Controls(fleet, desk, lambda topic, payload: None),
        desk=desk,
        assistant=None,
        push_to_talk=None,
        synthesize=None,
    )


@pytest.fixture
def server(fleet: Fleet) -> Iterator[StationServer]:
    with StationServer(make_app(fleet), port=free_port()) as running:
        yield running


@pytest.fixture
def guarded(fleet: Fleet) -> Iterator[StationServer]:
    with StationServer(make_app(fleet), port=free_port(), token=TOKEN) as running:
        yield running


def request(
    server: StationServer,
    method: str,
    path: str,
    body: bytes | None = None,
    headers: dict[str, str] | None = None,
) -> tuple[int, dict[str, str], bytes]:
    connection = http.client.HTTPConnection("127.0.0.1", server.port, timeout=10)
    try:
        connection.request(method, path, body=body, headers=headers or {})
        response = connection.getresponse()
        return response.status, dict(response.getheaders()), response.read()
    finally:
        connection.close()


def error(body: bytes) -> str:
    message: str = json.loads(body)["error"]
    return message


def test_the_page_and_its_files_are_served_with_their_types(server: StationServer) -> None:
    status, headers, page = request(server, "GET", "/")
    assert status == 200 and headers["Content-Type"] == "text/html; charset=utf-8"
    assert b"<title>VAHR station</title>" in page
    assert "script-src 'self'" in headers["Content-Security-Policy"]
    for path, kind in (
        ("/static/station.js", "text/javascript; charset=utf-8"),
        ("/static/station.css", "text/css; charset=utf-8"),
        ("/static/favicon.svg", "image/svg+xml"),
        ("/favicon.ico", "image/svg+xml"),
    ):
        status, headers, _ = request(server, "GET", path)
        assert (status, headers["Content-Type"]) == (200, kind), path


@pytest.mark.parametrize("path", ["/static/../server.py", "/static/nothing.js", "/etc/passwd"])
def test_nothing_else_is_served(server: StationServer, path: str) -> None:
    assert request(server, "GET", path)[0] == 404


def test_another_host_name_is_refused(server: StationServer) -> None:
    # A page elsewhere that rebinds its own name to 127.0.0.1 cannot read the station
    status, _, body = request(server, "GET", "/api/snapshot", headers={"Host": "evil.example"})
    assert status == 421 and "evil.example" in error(body)
    assert (
        request(server, "GET", "/api/health", headers={"Host": f"localhost:{server.port}"})[0]
        == 200
    )


def test_a_post_from_another_origin_or_of_another_type_is_refused(server: StationServer) -> None:
    body = json.dumps({}).encode()
    status, _, answer = request(
        server, "POST", "/api/stop", body,
        {"Content-Type": "application/json", "Origin": "http://evil.example"},
    )  # fmt: skip
    assert status == 403 and error(answer) == "requests from http://evil.example are not accepted"
    # A form on another site can only send simple types, which are refused
    status, _, answer = request(server, "POST", "/api/stop", body, {"Content-Type": "text/plain"})
    assert (status, error(answer)) == (415, "send application/json")
    assert request(server, "POST", "/api/voice", b"RIFF", {"Content-Type": "text/plain"})[0] == 415


def announce(server: StationServer, path: str, kind: str, length: int) -> tuple[int, str]:
    """Send only the headers of a POST of `length` bytes; the status and body answered."""
    with socket.create_connection(("127.0.0.1", server.port), timeout=10) as sock:
        sock.sendall(
            f"POST {path} HTTP/1.1\r\nHost: 127.0.0.1:{server.port}\r\n"
            f"Content-Type: {kind}\r\nContent-Length: {length}\r\n\r\n".encode()
        )
        answer = b""
        while chunk := sock.recv(65536):
            answer += chunk
    head, _, body = answer.partition(b"\r\n\r\n")
    return int(head.split()[1]), error(body)


def test_bodies_are_size_limited_before_they_are_read(server: StationServer) -> None:
    # The server answers from the headers alone, without waiting for the body
    status, message = announce(server, "/api/say", "application/json", MAX_JSON_BYTES + 1)
    assert status == 413 and message.startswith(f"the body is {MAX_JSON_BYTES + 1} bytes")
    status, _ = announce(server, "/api/voice", "audio/wav", MAX_AUDIO_BYTES + 1)
    assert status == 413


def test_a_chunked_body_and_other_methods_are_refused(server: StationServer) -> None:
    connection = http.client.HTTPConnection("127.0.0.1", server.port, timeout=10)
    connection.request(
        "POST", "/api/stop", body=iter([b"{}"]),
        headers={"Content-Type": "application/json", "Transfer-Encoding": "chunked"},
    )  # fmt: skip
    assert connection.getresponse().status == 411
    connection.close()
    assert request(server, "PUT", "/api/stop")[0] == 405
    assert (
        request(server, "POST", "/api/nothing", b"{}", {"Content-Type": "application/json"})[0]
        == 404
    )


def test_push_to_talk_without_a_recognizer_says_so(server: StationServer) -> None:
    status, _, answer = request(
        server, "POST", "/api/voice", b"RIFF", {"Content-Type": "audio/wav"}
    )
    assert status == 503 and "push-to-talk" in error(answer)


def test_the_event_stream_starts_with_a_snapshot_then_pushes_changes(
    server: StationServer,
) -> None:
    connection = http.client.HTTPConnection("127.0.0.1", server.port, timeout=10)
    connection.request("GET", "/api/stream")
    response = connection.getresponse()
    assert response.status == 200 and response.getheader("Content-Type") == "text/event-stream"

    def next_event() -> list[dict[str, Any]]:
        while True:
            line = response.fp.readline().decode()
            if line.startswith("data: "):
                events: list[dict[str, Any]] = json.loads(line.removeprefix("data: "))
                return events

    assert [m["type"] for m in next_event()] == ["snapshot"]
    # When something changes, the page is told without asking
    server.app.feed.set_experiment(None)
    assert next_event() == [{"type": "experiment", "status": None}]
    connection.close()


def test_off_loopback_a_token_is_made_and_required(fleet: Fleet) -> None:
    # 127.0.0.2 stands in for a lab network address (it never leaves this machine)
    with StationServer(make_app(fleet), host="127.0.0.2", port=free_port()) as running:
        assert running.token is not None and len(running.token) >= 20
        assert running.url.endswith(f"/?token={running.token}")
        connection = http.client.HTTPConnection("127.0.0.2", running.port, timeout=10)
        connection.request("GET", "/api/health")
        assert connection.getresponse().status == 401
        connection.close()


def test_the_token_opens_the_page_and_its_cookie_the_rest(guarded: StationServer) -> None:
    status, _, answer = request(guarded, "GET", "/")
    assert status == 401 and "token" in error(answer)
    status, headers, _ = request(guarded, "GET", f"/?token={TOKEN}")
    # The token sets the cookie, and the page is opened again without it in the address
    assert (status, headers["Location"]) == (303, "/")
    cookie = headers["Set-Cookie"].split(";")[0]
    assert "HttpOnly" in headers["Set-Cookie"] and "SameSite=Strict" in headers["Set-Cookie"]
    assert request(guarded, "GET", "/", headers={"Cookie": cookie})[0] == 200
    assert request(guarded, "GET", "/api/snapshot", headers={"Cookie": cookie})[0] == 200
    bearer = {"Authorization": f"Bearer {TOKEN}"}
    assert request(guarded, "GET", "/api/health", headers=bearer)[0] == 200
    assert (
        request(guarded, "GET", "/api/health", headers={"Cookie": "vahr_station=wrong"})[0] == 401
    )
