"""A keyboard session through the local stack: the plan goes to the experiment shadow over
the local data plane, robots keep their shadows in the local shadow service, and the
session is recorded, judged and reported."""

from __future__ import annotations

import json
from typing import TYPE_CHECKING

import boto3
import pytest

from tests.integration.experiment.experiment_robots import SPEED, RobotAgents
from vahr.cli import main
from vahr.local.alexa_host import serve_alexa
from vahr.plumbing.ports import free_port
from vahr.protocol import experiment_state_from_payload, robot_shadow_from_payload

if TYPE_CHECKING:
    from pathlib import Path

    from vahr.domain import Fleet
    from vahr.twin.stack import LocalStack


def test_a_keyboard_session_through_the_local_stack(
    tmp_path: Path,
    fleet: Fleet,
    stack: LocalStack,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
) -> None:
    for name in ("AWS_ACCESS_KEY_ID", "AWS_SECRET_ACCESS_KEY", "AWS_SESSION_TOKEN"):
        monkeypatch.delenv(name, raising=False)
    assert stack.mqtt_url is not None
    # The assistant answers the participant's weather questions in task II
    serve_alexa(stack)
    (tmp_path / "robots").mkdir()
    robots = RobotAgents(fleet, stack.mqtt_url, tmp_path / "robots", SPEED)
    robots.start()
    try:
        # When a simulated keyboard session runs against the stack's data plane and broker
        code = main(
            [
                "experiment",
                "--participant",
                "SIM03",
                "--method",
                "keyboard",
                "--trial",
                "1",
                "--seed",
                "8",
                "--log-dir",
                str(tmp_path / "logs"),
                "--broker",
                stack.mqtt_url,
                "--api",
                stack.api_url,
                "--simulate",
                "--speed-factor",
                str(SPEED),
                "--json",
            ]
        )
    finally:
        robots.stop()
    assert code == 0
    summary = json.loads(capsys.readouterr().out)
    # Then every task succeeded
    assert all(body["success"] for body in summary["verdict"]["tasks"].values()), summary
    # and the experiment thing's shadow holds the plan, read back through the data plane
    data = boto3.client(
        "iot-data",
        endpoint_url=stack.api_url,
        region_name="us-east-1",
        aws_access_key_id="x",
        aws_secret_access_key="x",
    )
    state = experiment_state_from_payload(
        data.get_thing_shadow(thingName=fleet.experiment_thing)["payload"].read()
    )
    assert state.session == "SIM03-keyboard-trial1"
    assert state.assignments == summary["plan"]["assignments"]
    assert state.weather == summary["plan"]["weather"]
    # and the robots ended where task III left them, as their shadows report
    for thing in fleet.robot_things:
        shadow = robot_shadow_from_payload(data.get_thing_shadow(thingName=thing)["payload"].read())
        assert shadow.reported.zone == "D"
    # When the report is made from the log, Then it has its figures
    assert (
        main(["report", "--from-log", str(tmp_path / "logs"), "--out", str(tmp_path / "out")]) == 0
    )
    assert (tmp_path / "out" / "objective.png").stat().st_size > 1000


def test_the_assistant_client_reports_a_missing_or_unreachable_assistant(
    stack: LocalStack,
) -> None:
    from vahr.errors import VahrError
    from vahr.plumbing.client import HttpAssistant

    # Given a data plane without the Alexa simulator attached, and a port nothing listens on
    missing = HttpAssistant(stack.api_url)
    unreachable = HttpAssistant(f"http://127.0.0.1:{free_port()}", timeout_s=2)
    # Then each utterance fails with one line naming the reason
    with pytest.raises(VahrError, match=r"answered 404"):
        missing.ask("tell placebot one to deliver a package to zone B")
    with pytest.raises(VahrError, match=r"^nothing answers at"):
        unreachable.ask("hello")
