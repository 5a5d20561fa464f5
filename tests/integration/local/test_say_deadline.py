"""A say request is never carried out after its asker was told it failed: it waits for the
system to be ready only while it can still answer in the asker's time, is refused with 503
having done nothing when it cannot, and a command its turn would send after the asker
stopped waiting is refused at the data plane. `GET /vahr/health` answers 503 naming what
the system still waits for."""

from __future__ import annotations

import threading
import time
import urllib.error
import urllib.request
from typing import TYPE_CHECKING, Any

import pytest

from vahr.assistant.deadline import REPLY_MARGIN_S, TURN_BUDGET_S, TurnDeadline
from vahr.errors import VahrError
from vahr.local.alexa_host import serve_alexa
from vahr.local.readiness import Readiness
from vahr.plumbing.client import call
from vahr.plumbing.mqtt import MqttClient
from vahr.plumbing.ports import free_port
from vahr.protocol import topics
from vahr.twin.stack import LocalStack, StackConfig

if TYPE_CHECKING:
    from collections.abc import Iterator

    from vahr.assistant.simulator import AlexaSimulator


class Switch:
    """What the system waits for, set by the test."""

    def __init__(self) -> None:
        self.missing = ["robots to come online: placebot1"]

    def __call__(self) -> list[str]:
        return list(self.missing)


class Starting:
    """A local stack whose system is still starting: its simulator and what it waits for."""

    def __init__(self, stack: LocalStack, switch: Switch, alexa: AlexaSimulator) -> None:
        self.stack, self.switch, self.alexa = stack, switch, alexa


@pytest.fixture(scope="module")
def starting(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Starting]:
    switch = Switch()
    readiness = Readiness(switch)
    config = StackConfig(
        state_dir=tmp_path_factory.mktemp("starting"),
        mqtts_port=free_port(),
        mqtt_port=free_port(),
        api_port=free_port(),
    )
    with (
        pytest.MonkeyPatch.context() as patch,
        LocalStack(config, awaiting=readiness.awaiting) as stack,
    ):
        patch.setenv("AWS_ACCESS_KEY_ID", "testing")
        patch.setenv("AWS_SECRET_ACCESS_KEY", "testing")
        patch.setenv("AWS_DEFAULT_REGION", "us-east-1")
        alexa = serve_alexa(stack, ack_timeout_s=0.2, readiness=readiness)
        yield Starting(stack, switch, alexa)


@pytest.fixture
def commands(starting: Starting) -> Iterator[list[bytes]]:
    """Every command published on the broker while the test runs."""
    stack = starting.stack
    seen: list[bytes] = []
    with MqttClient(stack.service_endpoint()) as watcher:
        watcher.subscribe(topics.ALL_ROBOT_CMDS, lambda _t, payload: seen.append(payload))
        watcher.subscribe(topics.FLEET_CMD, lambda _t, payload: seen.append(payload))
        yield seen


def _post_say(api: str, body: dict[str, Any]) -> tuple[int, dict[str, Any]]:
    try:
        return 200, call(api, "POST", "/vahr/say", body, timeout_s=30)
    except VahrError as err:
        return int(str(err).split(" answered ")[1].split(":")[0]), {"message": str(err)}


def test_while_robots_are_not_online_health_says_so_with_503(
    starting: Starting,
) -> None:
    stack = starting.stack
    with pytest.raises(urllib.error.HTTPError) as refused:
        urllib.request.urlopen(stack.api_url + "/vahr/health", timeout=5)
    assert refused.value.code == 503
    body = refused.value.read().decode()
    assert '"ready":false' in body.replace(" ", "")
    assert "placebot1" in body


def test_a_say_that_cannot_start_in_the_askers_time_is_refused_and_sends_nothing(
    starting: Starting, commands: list[bytes]
) -> None:
    stack = starting.stack
    # Given a system still starting, and an asker who waits 9.6 s (0.6 s to start in)
    timeout = TURN_BUDGET_S + REPLY_MARGIN_S + 0.6
    began = time.monotonic()
    status, answer = _post_say(
        stack.api_url, {"utterance": "send placebot one to zone b", "timeout_s": timeout}
    )
    waited = time.monotonic() - began
    # Then it is refused once the turn could no longer finish in time, saying why
    assert status == 503
    assert "still starting" in answer["message"] and "nothing was sent" in answer["message"]
    assert 0.5 <= waited < timeout
    time.sleep(0.5)
    assert commands == []


def test_a_say_waits_for_the_system_to_be_ready_then_runs(
    starting: Starting, commands: list[bytes]
) -> None:
    stack, switch = starting.stack, starting.switch
    # Given the system becomes ready a moment after the request came
    threading.Timer(0.5, lambda: switch.missing.clear()).start()
    status, turn = _post_say(
        stack.api_url, {"utterance": "send placebot one to zone b", "timeout_s": 30}
    )
    assert status == 200
    assert turn["intent"] == "NavigateIntent" and len(turn["commands"]) == 1
    deadline = time.monotonic() + 5
    while not commands and time.monotonic() < deadline:
        time.sleep(0.05)
    assert len(commands) == 1
    with urllib.request.urlopen(stack.api_url + "/vahr/health", timeout=5) as answer:
        assert answer.status == 200


def test_a_command_the_turn_sends_after_its_asker_stopped_waiting_is_refused(
    starting: Starting, commands: list[bytes]
) -> None:
    starting.switch.missing.clear()
    alexa = starting.alexa
    # Given a turn that started in time but whose asker has already stopped waiting
    now = time.monotonic()
    late = TurnDeadline(start_by=now + 10, answer_by=now - 0.1)
    turn = alexa.say("send placebot two to zone c", deadline=late)
    alexa.end_session()
    # Then nothing reaches the broker and the turn names no command
    time.sleep(0.5)
    assert commands == []
    assert turn.commands == []


def test_a_bad_timeout_is_one_line(starting: Starting) -> None:
    stack = starting.stack
    status, answer = _post_say(stack.api_url, {"utterance": "hello", "timeout_s": "soon"})
    assert status == 400
    assert "timeout_s: must be a number of seconds more than 0" in answer["message"]
