"""Dialog: a missing robot or zone is elicited with the valid choices; an unknown one is
elicited again; nothing is published and the session stays open meanwhile."""

from __future__ import annotations

from typing import Any

import pytest
from skill_testkit import published, reprompt, speech

from tests.conftest import load_event

ROBOTS = "placebot one, placebot two, or all robots"
ZONES = "the loading zone, zone A, zone B, zone C, or zone D"
DELIVERY_ZONES = "zone A, zone B, zone C, or zone D"


def elicited(response: dict[str, Any]) -> tuple[str, dict[str, Any]]:
    """The slot the skill asks for and the intent it sends back with the directive."""
    [directive] = response["response"]["directives"]
    assert directive["type"] == "Dialog.ElicitSlot"
    return directive["slotToElicit"], directive["updatedIntent"]


@pytest.mark.parametrize(
    ("event", "slot", "question"),
    [
        ("alexa_navigate_missing_zone", "zone", f"To which zone: {ZONES}?"),
        ("alexa_navigate_missing_robot", "robot", f"Which robot: {ROBOTS}?"),
        ("alexa_weather_delivery_missing_robot", "robot", f"Which robot: {ROBOTS}?"),
        (
            "alexa_navigate_zone_no_match",
            "zone",
            f"I don't know a zone called zone q. To which zone: {ZONES}?",
        ),
        (
            "alexa_navigate_robot_no_match",
            "robot",
            f"I don't know a robot called the blue robot. Which robot: {ROBOTS}?",
        ),
        (
            # Alexa matched "robot" to both robots: the skill asks which rather than take
            # the first.
            "alexa_navigate_robot_ambiguous",
            "robot",
            "Placebot one or placebot two?",
        ),
        (
            "alexa_deliver_to_loading",
            "zone",
            "Packages are picked up in the loading zone. Where should placebot one deliver "
            f"the package: {DELIVERY_ZONES}?",
        ),
        (
            "alexa_sequential_delivery_fleet",
            "firstRobot",
            "A sequential delivery needs one robot at a time. Which robot delivers first: "
            "placebot one or placebot two?",
        ),
        (
            "alexa_sequential_delivery_missing_second_zone",
            "secondZone",
            f"Where should placebot two deliver the package: {DELIVERY_ZONES}?",
        ),
    ],
)
def test_missing_or_unknown_slot_is_elicited_with_the_choices(
    skill: Any, aws: None, event: str, slot: str, question: str
) -> None:
    request = load_event(event)
    response = skill(request, None)
    slot_to_elicit, updated_intent = elicited(response)
    assert slot_to_elicit == slot
    assert speech(response) == question
    assert reprompt(response) == question
    assert response["response"]["shouldEndSession"] is False
    assert updated_intent["name"] == request["request"]["intent"]["name"]
    # The value that did not resolve is dropped, so the answer fills the slot afresh.
    assert "value" not in updated_intent["slots"][slot]
    assert published() == []


def test_elicitation_keeps_the_slots_already_given(skill: Any, aws: None) -> None:
    response = skill(load_event("alexa_navigate_zone_no_match"), None)
    _, updated_intent = elicited(response)
    assert updated_intent["slots"]["robot"]["value"] == "placebot two"


def test_the_same_robot_twice_in_a_sequential_delivery_is_asked_again(
    skill: Any, aws: None
) -> None:
    request = load_event("alexa_sequential_delivery")
    second = request["request"]["intent"]["slots"]["secondRobot"]
    first = request["request"]["intent"]["slots"]["firstRobot"]
    second.update({key: first[key] for key in ("value", "slotValue", "resolutions")})
    response = skill(request, None)
    assert elicited(response)[0] == "secondRobot"
    assert speech(response) == (
        "Placebot one already delivers first. Which robot delivers second: "
        "placebot one or placebot two?"
    )
    assert published() == []


def test_answered_elicitation_completes_the_command(skill: Any, robots: Any) -> None:
    # Given the zone was elicited and the person answered "zone d"
    request = load_event("alexa_navigate_missing_zone")
    request["session"]["new"] = False
    request["request"]["dialogState"] = "IN_PROGRESS"
    zone = request["request"]["intent"]["slots"]["zone"]
    authority = (
        "amzn1.er-authority.echo-sdk.amzn1.ask.skill.8b5f1c1e-3f0a-4c55-9a57-2f3d6f1e9a10.ZONE"
    )
    zone.update(
        {
            "value": "zone d",
            "resolutions": {
                "resolutionsPerAuthority": [
                    {
                        "authority": authority,
                        "status": {"code": "ER_SUCCESS_MATCH"},
                        "values": [{"value": {"name": "zone d", "id": "D"}}],
                    }
                ]
            },
        }
    )
    response = skill(request, None)
    assert [topic for topic, _ in published()] == ["vahr/robots/placebot2/cmd"]
    assert speech(response) == "Placebot two is on its way to zone D."
    assert "directives" not in response["response"]


def test_after_three_questions_the_skill_stops_asking(skill: Any, aws: None) -> None:
    # Given a person whose zone is misheard again and again
    request = load_event("alexa_navigate_zone_no_match")
    questions = []
    for _ in range(4):
        response = skill(request, None)
        questions.append(speech(response))
        request["session"]["attributes"] = response["sessionAttributes"]
    # Then the skill asked three times, then gave up with a hint and sent nothing
    assert questions[:3] == [questions[0]] * 3
    assert questions[3] == (
        "Sorry, I still did not get that, so I sent nothing. Try, for example: send placebot "
        "one to zone A."
    )
    assert response["response"]["shouldEndSession"] is True
    assert "directives" not in response["response"]
    assert published() == []


def test_a_slot_left_out_of_the_request_is_added_to_the_updated_intent(
    skill: Any, aws: None
) -> None:
    request = load_event("alexa_navigate_missing_zone")
    del request["request"]["intent"]["slots"]["zone"]
    slot, updated_intent = elicited(skill(request, None))
    assert slot == "zone"
    assert updated_intent["slots"]["zone"] == {"name": "zone", "confirmationStatus": "NONE"}


def test_a_robot_the_fleet_has_but_left_unresolved_is_asked_for_without_calling_it_unknown(
    skill: Any, aws: None
) -> None:
    # "placebot one" was said, but the words did not say whose it is (the NLU withheld it),
    # so it comes unresolved: the skill asks, and does not claim not to know placebot one
    request = load_event("alexa_navigate_robot_no_match")
    robot = request["request"]["intent"]["slots"]["robot"]
    robot["value"] = robot["slotValue"]["value"] = "placebot one"
    response = skill(request, None)
    assert elicited(response)[0] == "robot"
    assert speech(response) == f"Which robot: {ROBOTS}?"
    assert published() == []
