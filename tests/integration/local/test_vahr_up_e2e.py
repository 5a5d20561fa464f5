"""End to end: `vahr up` in the background, `vahr say` as a person, robots moving in the
simulator, and replies that reflect their acknowledgments."""

from __future__ import annotations

import json
import os
import queue
import signal
import socket
import subprocess
import sys
import threading
import time
import urllib.request
from pathlib import Path
from typing import IO, TYPE_CHECKING, Any

import pytest

from vahr.local.ports import LOOPBACK, free_port

if TYPE_CHECKING:
    from collections.abc import Iterator

ROOT = Path(__file__).resolve().parents[3]
VAHR = [sys.executable, "-m", "vahr.cli"]
START_TIMEOUT_S = 40.0


class Up:
    """A `vahr up --json` process and the JSON lines it prints."""

    def __init__(self, process: subprocess.Popen[str], endpoints: dict[str, Any]) -> None:
        self.process = process
        self.endpoints = endpoints
        self.lines: queue.Queue[dict[str, Any]] = queue.Queue()
        self._reader = threading.Thread(target=self._read, args=(process.stdout,), daemon=True)
        self._reader.start()

    def _read(self, stream: IO[str]) -> None:
        for line in stream:
            self.lines.put(json.loads(line))

    def wait_event(self, command_id: str, kind: str, timeout_s: float = 20.0) -> dict[str, Any]:
        deadline = time.monotonic() + timeout_s
        while True:
            event = self.lines.get(timeout=max(0.01, deadline - time.monotonic()))
            if event.get("command_id") == command_id and event.get("event") in (kind, "failed"):
                return event


def _env() -> dict[str, str]:
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    for name in ("AWS_ACCESS_KEY_ID", "AWS_SECRET_ACCESS_KEY", "AWS_PROFILE", "VAHR_API"):
        env.pop(name, None)
    return env


@pytest.fixture(scope="module")
def up(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Up]:
    state = tmp_path_factory.mktemp("up")
    api_port, mqtts_port = free_port(), free_port()
    process = subprocess.Popen(
        [*VAHR, "up", "--json", "--no-voice", "--state-dir", str(state),
         "--api-port", str(api_port), "--mqtts-port", str(mqtts_port), "--mqtt-port", "0",
         "--sim-speed-factor", "20"],
        cwd=ROOT, env=_env(), stdout=subprocess.PIPE, stderr=(state / "up.err").open("w"),
        text=True,
    )  # fmt: skip
    try:
        assert process.stdout is not None
        first = _first_line(process, START_TIMEOUT_S)
        assert first, (state / "up.err").read_text()
        yield Up(process, json.loads(first))
    finally:
        if process.poll() is None:
            process.send_signal(signal.SIGTERM)
            process.wait(timeout=30)


def _first_line(process: subprocess.Popen[str], timeout_s: float) -> str:
    box: queue.Queue[str] = queue.Queue()
    assert process.stdout is not None
    stream = process.stdout
    threading.Thread(target=lambda: box.put(stream.readline()), daemon=True).start()
    try:
        return box.get(timeout=timeout_s)
    except queue.Empty:
        return ""


def say(up: Up, utterance: str) -> dict[str, Any]:
    result = subprocess.run(
        [*VAHR, "say", "--json", "--api", up.endpoints["api"], utterance],
        cwd=ROOT, env=_env(), capture_output=True, text=True, timeout=30, check=True,
    )  # fmt: skip
    turn: dict[str, Any] = json.loads(result.stdout)
    return turn


def test_the_first_line_names_every_endpoint(up: Up) -> None:
    assert set(up.endpoints) == {"api", "mqtt", "mqtts", "ca", "dashboard"}
    assert up.endpoints["api"].startswith(f"http://{LOOPBACK}:")
    assert up.endpoints["mqtt"] is None  # --mqtt-port 0: no plaintext listener
    assert Path(up.endpoints["ca"]).read_text().startswith("-----BEGIN CERTIFICATE-----")


def test_a_spoken_command_moves_the_robot_and_the_reply_reflects_it(up: Up) -> None:
    # When the person asks for placebot one to go to zone B
    turn = say(up, "Alexa, ask robot fleet to send robot one to zone b")
    # Then the skill heard the intent, published one command and the robot acknowledged it
    assert turn["intent"] == "NavigateIntent"
    assert turn["slots"]["zone"] == {"value": "zone b", "id": "B"}
    assert len(turn["commands"]) == 1
    assert turn["speech"].startswith("Placebot one is on its way to zone B")
    assert turn["latency_ms"] > 0
    # And the robot arrives in the simulator
    arrived = up.wait_event(turn["commands"][0], "arrived")
    assert (arrived["event"], arrived["zone"]) == ("arrived", "B")
    # And asking where it is reports the shadow it updated
    status = say(up, "Alexa, ask robot fleet where is robot one")
    assert "zone B" in status["speech"]
    assert status["commands"] == []


def test_the_dashboard_and_status_show_the_robots(up: Up) -> None:
    with urllib.request.urlopen(up.endpoints["dashboard"], timeout=10) as page:
        assert page.headers["Content-Type"].startswith("text/html")
        assert b"VAHR on this machine" in page.read()
    with urllib.request.urlopen(up.endpoints["api"] + "/vahr/status", timeout=10) as answer:
        status = json.loads(answer.read())
    assert status["online"] == {"placebot1": True, "placebot2": True}
    assert status["robots"]["placebot2"]["connected"] is True


def test_a_session_keeps_going_until_the_person_leaves(up: Up) -> None:
    opened = say(up, "Alexa, open robot fleet")
    assert opened["session_open"] is True
    turn = say(up, "send all robots to the loading zone")
    assert turn["intent"] == "NavigateIntent"
    assert turn["slots"]["robot"]["id"] == "all"
    assert turn["session_open"] is True
    closed = say(up, "exit")
    assert closed["request_type"] == "SessionEndedRequest"
    assert closed["session_open"] is False


def test_the_console_reads_turns_from_standard_input(up: Up) -> None:
    result = subprocess.run(
        [*VAHR, "console", "--api", up.endpoints["api"]],
        input="Alexa, open robot fleet\nwhere is robot two\nexit\n",
        cwd=ROOT, env=_env(), capture_output=True, text=True, timeout=30, check=True,
    )  # fmt: skip
    replies = [line for line in result.stdout.splitlines() if line.startswith("alexa> ")]
    assert len(replies) == 3
    assert replies[0].startswith("alexa> Welcome to robot fleet")
    assert "[StatusIntent," in replies[1]
    assert "[SessionEndedRequest," in replies[2]


def test_a_taken_port_is_one_clear_line(tmp_path: Path) -> None:
    with socket.socket() as taken:
        taken.bind((LOOPBACK, 0))
        taken.listen()
        port = taken.getsockname()[1]
        result = subprocess.run(
            [*VAHR, "up", "--state-dir", str(tmp_path), "--api-port", str(port),
             "--mqtts-port", str(free_port()), "--mqtt-port", "0", "--no-voice"],
            cwd=ROOT, env=_env(), capture_output=True, text=True, timeout=30,
        )  # fmt: skip
    assert result.returncode == 2
    assert result.stderr.strip() == (
        f"vahr up: error: port {port} for the data-plane API is already in use on "
        f"{LOOPBACK}; stop what uses it or pick another port"
    )


def test_say_without_a_running_system_is_one_clear_line() -> None:
    port = free_port()
    result = subprocess.run(
        [*VAHR, "say", "--api", f"http://{LOOPBACK}:{port}", "hello"],
        cwd=ROOT, env=_env(), capture_output=True, text=True, timeout=30,
    )  # fmt: skip
    assert result.returncode == 2
    assert result.stderr.startswith(f"vahr say: error: nothing answers at http://{LOOPBACK}:{port}")
    assert len(result.stderr.strip().splitlines()) == 1


def test_sigterm_stops_every_process(tmp_path_factory: pytest.TempPathFactory, up: Up) -> None:
    # Runs last in this module: it stops the shared `vahr up`.
    children = subprocess.run(
        ["pgrep", "-P", str(up.process.pid)], capture_output=True, text=True, check=False
    ).stdout.split()
    assert children, "vahr up should have a broker and robot processes"
    up.process.send_signal(signal.SIGTERM)
    assert up.process.wait(timeout=30) == 0
    for pid in children:
        assert not Path(f"/proc/{pid}").exists() or _is_zombie(pid)


def _is_zombie(pid: str) -> bool:
    try:
        return Path(f"/proc/{pid}/stat").read_text().split()[2] == "Z"
    except OSError:
        return True
