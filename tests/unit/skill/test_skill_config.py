"""Configuration: every setting has a default, bad values are refused at cold start with the
variable named, and the skill id is enforced when set."""

from __future__ import annotations

from typing import Any

import pytest
from skill_testkit import published, speech

from skill import prompts
from skill.config import SkillConfig
from skill.errors import ConfigError
from skill.iot_data import create_client
from tests.conftest import load_event


def test_defaults_with_an_empty_environment() -> None:
    assert SkillConfig.from_env({}) == SkillConfig(
        data_endpoint=None, skill_id=None, ack_timeout_s=2.5, fleet_file=None, log_level="INFO"
    )


def test_every_variable_is_read() -> None:
    config = SkillConfig.from_env(
        {
            "VAHR_IOT_DATA_ENDPOINT": "abc123-ats.iot.eu-west-1.amazonaws.com",
            "VAHR_SKILL_ID": "amzn1.ask.skill.1234",
            "VAHR_ACK_TIMEOUT_S": "1.25",
            "VAHR_FLEET_FILE": "/opt/fleet.yaml",
            "VAHR_LOG_LEVEL": "debug",
            "VAHR_SKILL_ID_PARAMETER": "/vahr/Vahr/skill-id",
            "VAHR_ALLOW_ANY_SKILL": "true",
            "AWS_LAMBDA_FUNCTION_NAME": "Vahr-Skill",
        }
    )
    assert config == SkillConfig(
        data_endpoint="https://abc123-ats.iot.eu-west-1.amazonaws.com",
        skill_id="amzn1.ask.skill.1234",
        skill_id_parameter="/vahr/Vahr/skill-id",
        allow_any_skill=True,
        on_lambda=True,
        ack_timeout_s=1.25,
        fleet_file="/opt/fleet.yaml",
        log_level="DEBUG",
    )


def test_boto3s_own_endpoint_variable_wins_over_the_stacks() -> None:
    config = SkillConfig.from_env(
        {
            "AWS_ENDPOINT_URL_IOT_DATA_PLANE": "http://127.0.0.1:8080",
            "VAHR_IOT_DATA_ENDPOINT": "abc123-ats.iot.eu-west-1.amazonaws.com",
        }
    )
    assert config.data_endpoint == "http://127.0.0.1:8080"


@pytest.mark.parametrize(
    ("variable", "value", "message"),
    [
        ("VAHR_ACK_TIMEOUT_S", "soon", "VAHR_ACK_TIMEOUT_S: 'soon' is not a number of seconds"),
        ("VAHR_ACK_TIMEOUT_S", "9", "VAHR_ACK_TIMEOUT_S: 9 is out of range"),
        ("VAHR_ACK_TIMEOUT_S", "0", "VAHR_ACK_TIMEOUT_S: 0 is out of range"),
        ("VAHR_LOG_LEVEL", "chatty", "VAHR_LOG_LEVEL: 'chatty' is not one of DEBUG"),
        ("VAHR_ALLOW_ANY_SKILL", "maybe", "VAHR_ALLOW_ANY_SKILL: 'maybe' is not true or false"),
    ],
)
def test_bad_values_name_the_variable(variable: str, value: str, message: str) -> None:
    with pytest.raises(ConfigError, match=message):
        SkillConfig.from_env({variable: value})


def test_no_region_and_no_endpoint_is_a_config_error(monkeypatch: pytest.MonkeyPatch) -> None:
    for name in ("AWS_REGION", "AWS_DEFAULT_REGION", "AWS_CONFIG_FILE", "AWS_PROFILE"):
        monkeypatch.delenv(name, raising=False)
    monkeypatch.setenv("AWS_CONFIG_FILE", "/nonexistent")
    with pytest.raises(ConfigError, match="no AWS region"):
        create_client(SkillConfig())


def test_a_local_endpoint_needs_no_region(monkeypatch: pytest.MonkeyPatch) -> None:
    for name in ("AWS_REGION", "AWS_DEFAULT_REGION"):
        monkeypatch.delenv(name, raising=False)
    monkeypatch.setenv("AWS_CONFIG_FILE", "/nonexistent")
    client = create_client(SkillConfig(data_endpoint="http://127.0.0.1:9"))
    assert client.meta.endpoint_url == "http://127.0.0.1:9"
    assert client.meta.region_name == "us-east-1"


def test_skill_id_is_enforced_when_configured(make_skill: Any, robots: Any) -> None:
    # Given the skill configured for another skill's id
    skill = make_skill(skill_id="amzn1.ask.skill.00000000-0000-0000-0000-000000000000")
    # When a request for this skill arrives
    response = skill(load_event("alexa_navigate"), None)
    # Then it is answered with a sentence saying so, before any handler runs, and nothing
    # is published (tests/unit/skill/test_skill_gate.py has every case)
    assert speech(response) == prompts.NOT_THIS_SKILL
    assert published() == []


def test_matching_skill_id_is_served(make_skill: Any, robots: Any) -> None:
    event = load_event("alexa_navigate")
    skill = make_skill(skill_id=event["context"]["System"]["application"]["applicationId"])
    assert speech(skill(event, None)) == "Placebot one is on its way to zone A."
