"""Acceptance in the local stack as a user runs it: `vahr up`, then a person asks by voice
(`vahr say`) for a weather delivery. The robot asks the room assistant, hears the skill's
answer as audio, and delivers to A when sunny and to C when rainy; its events carry the
recognized text. Robots connect over mTLS with certificates from the local CA."""

from __future__ import annotations

import json
import os
import select
import signal
import subprocess
import sys
import time
from pathlib import Path
from typing import TYPE_CHECKING, Any

import pytest

from tests.integration.voice.test_voice_weather_task import EventLog
from vahr.plumbing.lifetime import spawn
from vahr.plumbing.mqtt import MqttClient, MqttEndpoint
from vahr.plumbing.ports import free_port
from vahr.protocol import topics
from vahr.protocol.shadow import ExperimentState

if TYPE_CHECKING:
    from collections.abc import Iterator

ROOT = Path(__file__).resolve().parents[3]
UP_TIMEOUT_S = 60.0


def read_line(process: subprocess.Popen[bytes], timeout_s: float) -> bytes:
    assert process.stdout is not None
    ready, _, _ = select.select([process.stdout], [], [], timeout_s)
    if not ready:
        raise AssertionError(f"vahr up printed nothing within {timeout_s} s")
    return process.stdout.readline()


@pytest.fixture(scope="module")
def system(tmp_path_factory: pytest.TempPathFactory) -> Iterator[dict[str, Any]]:
    state = tmp_path_factory.mktemp("up")
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    process = spawn(
        [sys.executable, "-m", "vahr.cli", "up", "--state-dir", str(state),
         "--api-port", str(free_port()), "--dev-plaintext", "--mqtt-port", str(free_port()),
         "--mqtts-port", str(free_port()), "--station-port", "0",
         "--sim-speed-factor", "20", "--json"],
        started_for=state, cwd=ROOT, env=env, stdout=subprocess.PIPE,
        stderr=(state / "up.err").open("wb"), stdin=subprocess.DEVNULL,
    )  # fmt: skip
    try:
        endpoints = json.loads(read_line(process, UP_TIMEOUT_S))
        port = int(endpoints["mqtt"].rsplit(":", 1)[1])
        online: set[str] = set()
        watcher = MqttClient(MqttEndpoint(port=port)).connect()
        watcher.subscribe(
            topics.ALL_PRESENCE,
            lambda t, p: online.add(t.split("/")[2]) if json.loads(p).get("online") else None,
        )
        deadline = time.monotonic() + UP_TIMEOUT_S
        while "placebot1" not in online and time.monotonic() < deadline:
            time.sleep(0.1)
        watcher.stop()
        assert "placebot1" in online, (state / "up.err").read_text()[-2000:]
        yield {**endpoints, "port": port, "state": state, "env": env}
    finally:
        process.send_signal(signal.SIGINT)
        try:
            process.wait(30)
        except subprocess.TimeoutExpired:
            process.kill()
            process.wait(5)
        if process.stdout is not None:
            process.stdout.close()


def set_weather(api: str, weather: str) -> None:
    import boto3

    client = boto3.client(
        "iot-data", endpoint_url=api, region_name="us-east-1",
        aws_access_key_id="local", aws_secret_access_key="local",
    )  # fmt: skip
    payload = ExperimentState(weather=weather).to_payload()  # type: ignore[arg-type]
    client.update_thing_shadow(thingName="vahr-experiment", payload=payload)


@pytest.mark.slow
@pytest.mark.parametrize(("weather", "zone"), [("sunny", "A"), ("rainy", "C")])
def test_a_weather_delivery_asked_by_voice_ends_in_the_weathers_zone(
    system: dict[str, Any], weather: str, zone: str
) -> None:
    # Given the experiment's weather
    set_weather(system["api"], weather)
    log = EventLog(system["port"], "placebot1")
    try:
        # When the person says the command to the assistant
        said = subprocess.run(
            [sys.executable, "-m", "vahr.cli", "say",
             "have placebot one deliver based on the weather", "--api", system["api"], "--json"],
            cwd=ROOT, env=system["env"], capture_output=True, timeout=30, check=True,
        )  # fmt: skip
        reply = json.loads(said.stdout)
        assert reply["intent"] == "WeatherDeliveryIntent"
        (command_id,) = reply["commands"]
        # Then the robot delivers to the weather's zone
        delivered = log.wait_for("delivered", 60.0, command_id)
        assert (delivered["event"], delivered["zone"]) == ("delivered", zone), log.events
        # And its events show the question, the answer it heard and how it understood it
        mine = [e for e in log.events if e.get("command_id") == command_id]
        assert [e["text"] for e in mine if e["event"] == "said"] == [
            "Alexa, ask robot fleet what the weather is",
            f"Thank you. It is {weather}, so I am delivering to zone {zone}.",
        ]
        assert [e["text"] for e in mine if e["event"] == "heard"] == [f"the weather is {weather}"]
        assert [e["intent"] for e in mine if e["event"] == "interpreted"] == [weather]
    finally:
        log.client.stop()
