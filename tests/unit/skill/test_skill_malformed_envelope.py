"""An envelope the ASK SDK cannot read still gets valid speech (found by tests/fuzz/)."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from skill_testkit import speech

from skill import prompts
from tests.conftest import load_event

if TYPE_CHECKING:
    from collections.abc import Callable


def test_an_envelope_the_sdk_cannot_read_gets_the_safe_sentence(
    make_skill: Callable[..., Callable[[dict[str, Any], Any], dict[str, Any]]],
) -> None:
    # Given an envelope whose request type no Alexa request has
    event = load_event("alexa_navigate")
    event["request"]["type"] = " "
    # When the skill handles it
    response = make_skill()(event, None)
    # Then it answers with the safe sentence instead of failing the invocation
    assert speech(response) == prompts.GENERIC_ERROR
    assert response["response"]["shouldEndSession"] is True


def test_an_envelope_for_another_skill_is_still_refused(
    make_skill: Callable[..., Callable[[dict[str, Any], Any], dict[str, Any]]],
) -> None:
    event = load_event("alexa_navigate")
    event["context"]["System"]["application"]["applicationId"] = "amzn1.ask.skill.other"
    response = make_skill(skill_id="amzn1.ask.skill.8b5f1c1e-3f0a-4c55-9a57-2f3d6f1e9a10")(
        event, None
    )
    assert speech(response) == prompts.NOT_THIS_SKILL
