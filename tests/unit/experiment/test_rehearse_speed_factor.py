"""`vahr rehearse --api` adopts the running stack's speed factor, or refuses another one in
one line, instead of measuring task times off by the ratio."""

from __future__ import annotations

import json
import subprocess
import sys
import threading
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from typing import TYPE_CHECKING, Any

import pytest

from vahr.commands.rehearse import DEFAULT_SPEED, speed_factor
from vahr.errors import VahrError

if TYPE_CHECKING:
    from collections.abc import Iterator


def health_server(answer: dict[str, Any]) -> ThreadingHTTPServer:
    class Health(BaseHTTPRequestHandler):
        def do_GET(self) -> None:  # noqa: N802 - http.server's name
            body = json.dumps(answer).encode()
            self.send_response(200 if self.path == "/vahr/health" else 404)
            self.send_header("Content-Length", str(len(body)))
            self.end_headers()
            self.wfile.write(body)

        def log_message(self, *args: object) -> None:
            pass

    return ThreadingHTTPServer(("127.0.0.1", 0), Health)


@pytest.fixture
def stack_at_x1() -> Iterator[str]:
    server = health_server({"ok": True, "sim_speed_factor": 1.0})
    thread = threading.Thread(target=server.serve_forever, daemon=True)
    thread.start()
    try:
        yield f"http://127.0.0.1:{server.server_address[1]}"
    finally:
        server.shutdown()
        server.server_close()
        thread.join(timeout=5)


def test_a_running_stacks_factor_is_adopted(stack_at_x1: str) -> None:
    assert speed_factor(stack_at_x1, None) == 1.0
    assert speed_factor(stack_at_x1, 1.0) == 1.0
    assert speed_factor(None, None) == DEFAULT_SPEED


def test_another_factor_is_refused_in_one_line(stack_at_x1: str) -> None:
    # Given a stack at x1, When the rehearsal is asked for x30 (the old silent failure)
    result = subprocess.run(
        [sys.executable, "-m", "vahr.cli", "rehearse", "--api", stack_at_x1,
         "--broker", "mqtt://127.0.0.1:1", "--speed-factor", "30", "--out", "unused"],
        capture_output=True, text=True, timeout=60,
    )  # fmt: skip
    # Then it stops before anything runs, saying what to do
    assert result.returncode != 0
    assert result.stderr.splitlines() == [
        "vahr rehearse: error: --speed-factor 30 differs from the running stack's x1 "
        "(vahr up --sim-speed-factor 1): drop --speed-factor to adopt it"
    ]


def test_a_stack_that_does_not_tell_needs_the_flag() -> None:
    server = health_server({"ok": True})
    thread = threading.Thread(target=server.serve_forever, daemon=True)
    thread.start()
    try:
        api = f"http://127.0.0.1:{server.server_address[1]}"
        with pytest.raises(VahrError, match="does not tell its robots' speed factor"):
            speed_factor(api, None)
        assert speed_factor(api, 12.0) == 12.0
    finally:
        server.shutdown()
        server.server_close()
        thread.join(timeout=5)
