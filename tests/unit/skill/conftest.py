"""Fixtures for the skill's tests: moto with the fleet's things, robot doubles, the skill."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import boto3
import pytest
from moto import mock_aws
from skill_testkit import REGION, RobotDoubles

from tests.support.shared_models import default_session
from vahr.protocol import Reported

if TYPE_CHECKING:
    from collections.abc import Callable, Iterator

    from vahr.domain import Fleet


@pytest.fixture
def aws(monkeypatch: pytest.MonkeyPatch, fleet: Fleet) -> Iterator[None]:
    """moto with only a region configured, and a thing for each robot and the experiment."""
    for name in (
        "AWS_ENDPOINT_URL",
        "AWS_ENDPOINT_URL_IOT_DATA_PLANE",
        "VAHR_IOT_DATA_ENDPOINT",
        "VAHR_SKILL_ID",
        "VAHR_SKILL_ID_PARAMETER",
        "VAHR_ALLOW_ANY_SKILL",
        "AWS_LAMBDA_FUNCTION_NAME",
        "VAHR_ACK_TIMEOUT_S",
        "VAHR_FLEET_FILE",
        "AWS_PROFILE",
    ):
        monkeypatch.delenv(name, raising=False)
    monkeypatch.setenv("AWS_DEFAULT_REGION", REGION)
    with mock_aws():
        default_session()
        iot = boto3.client("iot", region_name=REGION)
        for thing in (*fleet.robot_things, fleet.experiment_thing):
            iot.create_thing(thingName=thing)
        yield


@pytest.fixture
def iot_data(aws: None) -> Any:
    return boto3.client("iot-data", region_name=REGION)


@pytest.fixture
def robots(iot_data: Any, fleet: Fleet) -> Iterator[RobotDoubles]:
    doubles = RobotDoubles(iot_data, fleet)
    for thing in fleet.robot_things:
        doubles.report(thing, Reported(status="idle", zone="LOADING", connected=True))
    doubles.start()
    try:
        yield doubles
    finally:
        doubles.stop()


@pytest.fixture
def make_skill(aws: None) -> Callable[..., Callable[[dict[str, Any], Any], dict[str, Any]]]:
    """A fresh skill handler inside moto; keyword arguments override SkillConfig fields."""
    from skill.app import make_lambda_handler
    from skill.config import SkillConfig

    def make(**settings: Any) -> Callable[[dict[str, Any], Any], dict[str, Any]]:
        return make_lambda_handler(SkillConfig(**{"ack_timeout_s": 1.5, **settings}))

    return make


@pytest.fixture
def skill(make_skill: Callable[..., Any]) -> Callable[[dict[str, Any], Any], dict[str, Any]]:
    handler: Callable[[dict[str, Any], Any], dict[str, Any]] = make_skill()
    return handler
