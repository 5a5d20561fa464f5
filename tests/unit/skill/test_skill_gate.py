"""The skill fails closed: on Lambda it serves only its own skill's requests, and with no
skill id configured it serves none, unless the deployment said any skill may call it.

Real ASK envelopes under moto; what a user would observe is asserted: the words spoken (a
valid Alexa answer every time), the messages published (none when refused), and the log
line naming the applicationId refused.
"""

from __future__ import annotations

import json
import logging
from typing import TYPE_CHECKING, Any

import boto3
import pytest
from skill_testkit import REGION, published, speech

from skill import prompts
from skill.app import make_lambda_handler
from skill.config import SkillConfig
from skill.skill_gate import ANOTHER_SKILL, NO_APPLICATION_ID, NO_SKILL_ID, SkillGate
from tests.conftest import load_event

if TYPE_CHECKING:
    from collections.abc import Callable

THIS_SKILL = "amzn1.ask.skill.8b5f1c1e-3f0a-4c55-9a57-2f3d6f1e9a10"  # tests/events' skill
OTHER_SKILL = "amzn1.ask.skill.00000000-0000-4000-8000-000000000000"
SERVED = "Placebot one is on its way to zone A."


def refusals(caplog: pytest.LogCaptureFixture) -> list[dict[str, Any]]:
    lines = [json.loads(r.getMessage()) for r in caplog.records if r.name == "skill"]
    return [line for line in lines if line["event"] == "request_refused"]


def on_lambda(monkeypatch: pytest.MonkeyPatch, **variables: str) -> Any:
    """The handler as Lambda's runtime builds it: from the environment, function name set."""
    monkeypatch.setenv("AWS_LAMBDA_FUNCTION_NAME", "Vahr-SkillFunction")
    for name, value in variables.items():
        monkeypatch.setenv(name, value)
    return make_lambda_handler(SkillConfig.from_env())


def test_on_lambda_without_a_skill_id_nothing_is_served(
    aws: None, robots: Any, monkeypatch: pytest.MonkeyPatch, caplog: pytest.LogCaptureFixture
) -> None:
    caplog.set_level(logging.INFO, logger="skill")
    # Given the function deployed without a skill id
    skill = on_lambda(monkeypatch)
    # When a genuine-looking request to send a robot arrives
    response = skill(load_event("alexa_navigate"), None)
    # Then Alexa gets a valid answer that says nothing was sent, and nothing was
    assert response["version"] == "1.0"
    assert speech(response) == prompts.NOT_THIS_SKILL
    assert response["response"]["shouldEndSession"] is True
    assert published() == []
    # And one log line names what was refused and why
    assert [(r["reason"], r["application_id"]) for r in refusals(caplog)] == [
        (NO_SKILL_ID, THIS_SKILL)
    ]


def test_on_lambda_only_the_configured_skill_is_served(
    aws: None, robots: Any, monkeypatch: pytest.MonkeyPatch, caplog: pytest.LogCaptureFixture
) -> None:
    caplog.set_level(logging.INFO, logger="skill")
    skill = on_lambda(monkeypatch, VAHR_SKILL_ID=THIS_SKILL)
    foreign = load_event("alexa_navigate")
    foreign["context"]["System"]["application"]["applicationId"] = OTHER_SKILL
    foreign["session"]["application"]["applicationId"] = OTHER_SKILL
    assert speech(skill(foreign, None)) == prompts.NOT_THIS_SKILL
    assert published() == []
    assert [(r["reason"], r["application_id"]) for r in refusals(caplog)] == [
        (ANOTHER_SKILL, OTHER_SKILL)
    ]
    # The skill's own request is served as ever
    assert speech(skill(load_event("alexa_navigate"), None)) == SERVED
    assert len(published()) == 1


def test_a_session_of_another_skill_is_refused_even_with_this_skills_context(
    make_skill: Callable[..., Any], robots: Any
) -> None:
    event = load_event("alexa_navigate")
    event["session"]["application"]["applicationId"] = OTHER_SKILL
    assert speech(make_skill(skill_id=THIS_SKILL)(event, None)) == prompts.NOT_THIS_SKILL
    assert published() == []


def test_an_envelope_without_an_application_id_is_refused(
    make_skill: Callable[..., Any], robots: Any
) -> None:
    event = load_event("alexa_navigate")
    del event["context"]["System"]["application"]
    del event["session"]["application"]
    assert speech(make_skill(skill_id=THIS_SKILL)(event, None)) == prompts.NOT_THIS_SKILL
    assert published() == []


def test_a_refusal_is_spoken_in_the_requests_language(
    make_skill: Callable[..., Any], robots: Any
) -> None:
    from skill.catalog import replies

    response = make_skill(skill_id=OTHER_SKILL)(load_event("alexa_navigate_de"), None)
    assert speech(response) == replies("de-DE")["NOT_THIS_SKILL"]
    # And the next English request is answered in English
    response = make_skill(skill_id=OTHER_SKILL)(load_event("alexa_navigate"), None)
    assert speech(response) == prompts.NOT_THIS_SKILL


def test_allowing_any_skill_must_be_said_and_is_logged(
    aws: None, robots: Any, monkeypatch: pytest.MonkeyPatch, caplog: pytest.LogCaptureFixture
) -> None:
    caplog.set_level(logging.INFO, logger="skill")
    skill = on_lambda(monkeypatch, VAHR_ALLOW_ANY_SKILL="true")
    event = load_event("alexa_navigate")
    event["context"]["System"]["application"]["applicationId"] = OTHER_SKILL
    assert speech(skill(event, None)) == SERVED
    events = [json.loads(r.getMessage())["event"] for r in caplog.records if r.name == "skill"]
    assert "any_skill_allowed" in events


def test_off_lambda_without_a_skill_id_requests_are_served(
    make_skill: Callable[..., Any], robots: Any
) -> None:
    # (Tests and tools build the handler in-process; there is no function ARN to learn.)
    assert speech(make_skill()(load_event("alexa_navigate"), None)) == SERVED


def test_the_skill_id_can_come_from_an_ssm_parameter_written_after_the_skill(
    aws: None, robots: Any, monkeypatch: pytest.MonkeyPatch, caplog: pytest.LogCaptureFixture
) -> None:
    caplog.set_level(logging.INFO, logger="skill")
    # Given a function told to read its skill id from a parameter that does not exist yet
    # (the stack writes it once the skill exists)
    skill = on_lambda(monkeypatch, VAHR_SKILL_ID_PARAMETER="/vahr/Vahr/skill-id")
    # Then requests are refused meanwhile, the failed read logged
    assert speech(skill(load_event("alexa_navigate"), None)) == prompts.NOT_THIS_SKILL
    logged = [json.loads(r.getMessage())["event"] for r in caplog.records if r.name == "skill"]
    assert "skill_id_unavailable" in logged
    assert published() == []
    # And once it holds the id, the skill's requests are served and others still refused
    ssm = boto3.client("ssm", region_name=REGION)
    ssm.put_parameter(Name="/vahr/Vahr/skill-id", Value=THIS_SKILL, Type="String")
    assert speech(skill(load_event("alexa_navigate"), None)) == SERVED
    foreign = load_event("alexa_navigate")
    foreign["context"]["System"]["application"]["applicationId"] = OTHER_SKILL
    assert speech(skill(foreign, None)) == prompts.NOT_THIS_SKILL
    assert len(published()) == 1


@pytest.mark.parametrize(
    ("gate", "event", "expected"),
    [
        (SkillGate(None, on_lambda=True), {}, NO_SKILL_ID),
        (SkillGate(None, allow_any_skill=True, on_lambda=True), {}, None),
        (SkillGate(None), {}, None),
        (SkillGate(THIS_SKILL), {}, NO_APPLICATION_ID),
        (SkillGate(THIS_SKILL), {"context": "not an object"}, NO_APPLICATION_ID),
        (SkillGate(THIS_SKILL), {"session": {"application": {"applicationId": 7}}}, ANOTHER_SKILL),
        (
            SkillGate(THIS_SKILL),
            {"context": {"System": {"application": {"applicationId": THIS_SKILL}}}},
            None,
        ),
    ],
)
def test_the_rule(gate: SkillGate, event: dict[str, Any], expected: str | None) -> None:
    assert gate.refusal(event) == expected
