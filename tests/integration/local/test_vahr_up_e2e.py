"""End to end: `vahr up` in the background, `vahr say` as a person, robots moving in the
simulator, and replies that reflect their acknowledgments."""

from __future__ import annotations

import http.client
import json
import signal
import socket
import subprocess
import sys
import time
import urllib.request
from pathlib import Path
from typing import TYPE_CHECKING, Any
from urllib.parse import urlsplit

import pytest

from tests.support.vahr_up import ROOT, VAHR, Up, clean_env, start_up, stop_up
from tests.support.vahr_up import say as say_to
from vahr.plumbing.ports import LOOPBACK, free_port

if TYPE_CHECKING:
    from collections.abc import Iterator


@pytest.fixture(scope="module")
def up(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Up]:
    state = tmp_path_factory.mktemp("up")
    running = start_up(state, "--station-port", str(free_port()), "--sim-speed-factor", "20")
    try:
        yield running
    finally:
        stop_up(running.process)


def say(up: Up, utterance: str) -> dict[str, Any]:
    return say_to(up.endpoints["api"], utterance)


def test_the_first_line_names_every_endpoint(up: Up) -> None:
    assert set(up.endpoints) == {"api", "mqtt", "mqtts", "ca", "station", "dashboard"}
    assert up.endpoints["station"].startswith(f"http://{LOOPBACK}:")
    assert up.endpoints["dashboard"] == up.endpoints["station"]
    assert up.endpoints["api"].startswith(f"http://{LOOPBACK}:")
    # No plaintext listener unless asked for (--dev-plaintext)
    assert up.endpoints["mqtt"] is None
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


def test_boto3_with_dummy_credentials_commands_a_robot(up: Up) -> None:
    # Given boto3 as a user's script would run it: the endpoint and dummy keys in its
    # environment, nothing else (a subprocess, so no state of this test leaks in)
    script = (
        "import boto3, json\n"
        "client = boto3.client('iot-data')\n"
        "command = {'id': 'boto3-1', 'action': 'navigate', 'params': {'zone': 'C'},\n"
        "           'issued_at': '2026-01-01T00:00:00Z', 'source': 'console'}\n"
        "client.publish(topic='vahr/robots/placebot2/cmd', qos=1,\n"
        "               payload=json.dumps(command).encode())\n"
        "print(client.get_thing_shadow(thingName='placebot2')['payload'].read().decode())\n"
    )
    env = {
        **clean_env(),
        "AWS_ACCESS_KEY_ID": "x",
        "AWS_SECRET_ACCESS_KEY": "x",
        "AWS_DEFAULT_REGION": "us-east-1",
        "AWS_ENDPOINT_URL_IOT_DATA_PLANE": up.endpoints["api"],
    }
    done = subprocess.run(
        [sys.executable, "-c", script], env=env, capture_output=True, text=True, timeout=60
    )
    assert done.returncode == 0, done.stderr
    assert json.loads(done.stdout)["state"]["reported"]["connected"] is True
    # Then the robot drives there
    arrived = up.wait_event("boto3-1", "arrived")
    assert (arrived["event"], arrived["zone"]) == ("arrived", "C")


def forge(api: str, path: str, body: dict[str, Any], headers: dict[str, str]) -> int:
    """POST `body` to the data plane with `headers` as a web page's browser could send them
    (Host included); the HTTP status it answers with."""
    address = urlsplit(api)
    connection = http.client.HTTPConnection(address.hostname, address.port, timeout=10)
    try:
        connection.putrequest("POST", path, skip_host="Host" in headers)
        for name, value in headers.items():
            connection.putheader(name, value)
        payload = json.dumps(body).encode()
        connection.putheader("Content-Length", str(len(payload)))
        connection.endheaders(payload)
        return connection.getresponse().status
    finally:
        connection.close()


def test_what_a_web_page_can_send_moves_no_robot(up: Up) -> None:
    api = up.endpoints["api"]
    command = {"action": "navigate", "params": {"zone": "D"}, "source": "console",
               "issued_at": "2026-01-01T00:00:00Z"}  # fmt: skip
    topic = "/topics/vahr/robots/placebot1/cmd?qos=1"
    # When a page sends commands as a browser can without asking first: a text/plain POST
    # from a foreign origin, a POST marked cross-site, a name rebound to 127.0.0.1, and a
    # desired command in the shadow
    forged = {
        "forged-origin": (topic, {"Content-Type": "text/plain", "Origin": "https://evil.example"}),
        "forged-site": (topic, {"Content-Type": "application/json", "Sec-Fetch-Site": "cross-site"}),
        "forged-host": (topic, {"Content-Type": "application/json", "Host": "evil.example"}),
        "forged-plain": (topic, {"Content-Type": "text/plain"}),
    }  # fmt: skip
    statuses = {
        name: forge(api, path, {**command, "id": name}, headers)
        for name, (path, headers) in forged.items()
    }
    desired = {"state": {"desired": {"command": {**command, "id": "forged-shadow"}}}}
    statuses["forged-shadow"] = forge(
        api, "/things/placebot1/shadow", desired, {"Content-Type": "text/plain"}
    )
    # Then each is refused
    assert statuses == {
        "forged-origin": 403, "forged-site": 403, "forged-host": 421, "forged-plain": 415,
        "forged-shadow": 415,
    }  # fmt: skip
    # And nothing reached the robot: a command sent as the repository's clients send it
    # (JSON, no page's headers) is the first it acknowledges
    marker = {**command, "id": "after-the-forgeries", "params": {"zone": "A"}}
    assert forge(api, topic, marker, {"Content-Type": "application/json"}) == 200
    seen: list[dict[str, Any]] = []
    deadline = time.monotonic() + 20
    while not any(line.get("command_id") == marker["id"] for line in seen):
        seen.append(up.lines.get(timeout=max(0.01, deadline - time.monotonic())))
    assert not [line for line in seen if str(line.get("command_id", "")).startswith("forged")]
    shadow = json.loads(urllib.request.urlopen(f"{api}/things/placebot1/shadow", timeout=10).read())
    assert "forged" not in json.dumps(shadow)


def test_the_old_dashboard_leads_to_the_station_and_status_shows_the_robots(up: Up) -> None:
    # The data plane's /vahr/dashboard now redirects to the operator station's page
    with urllib.request.urlopen(up.endpoints["api"] + "/vahr/dashboard", timeout=10) as page:
        assert page.url == up.endpoints["station"]
        assert page.headers["Content-Type"].startswith("text/html")
        assert b"<title>VAHR station</title>" in page.read()
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
        cwd=ROOT, env=clean_env(), capture_output=True, text=True, timeout=30, check=True,
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
             "--mqtts-port", str(free_port()), "--mqtt-port", "0", "--no-voice",
             "--station-port", str(free_port())],
            cwd=ROOT, env=clean_env(), capture_output=True, text=True, timeout=30,
        )  # fmt: skip
    assert result.returncode == 2
    assert result.stderr.strip() == (
        f"vahr up: error: port {port} for the data-plane API is already in use on "
        f"{LOOPBACK}; stop what uses it or pick another port"
    )


def test_a_plaintext_port_without_asking_for_the_listener_is_one_clear_line(
    tmp_path: Path,
) -> None:
    result = subprocess.run(
        [*VAHR, "up", "--state-dir", str(tmp_path / "state"), "--mqtt-port", "1999"],
        cwd=ROOT, env=clean_env(), capture_output=True, text=True, timeout=30,
    )  # fmt: skip
    assert result.returncode == 2
    assert result.stderr == (
        "vahr up: error: --mqtt-port 1999: the plaintext listener is off; add --dev-plaintext "
        "to open it (any program on this machine can then command the robots), or connect "
        "to --mqtts-port with a certificate\n"
    )
    assert not (tmp_path / "state").exists()


def test_say_without_a_running_system_is_one_clear_line() -> None:
    port = free_port()
    result = subprocess.run(
        [*VAHR, "say", "--api", f"http://{LOOPBACK}:{port}", "hello"],
        cwd=ROOT, env=clean_env(), capture_output=True, text=True, timeout=30,
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
