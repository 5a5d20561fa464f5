"""Corrections, undo and the dialog's confirmations under the real skill with moto: "no,
zone b" sends the same robot to zone B, "I meant placebot two" moves the other robot and
stops the first only, "cancel that" stops only the robot the last command went to, and a
value heard two ways is asked about by name instead of acted on."""

from __future__ import annotations

import json
from typing import Any

from skill_testkit import published, reprompt, speech

from tests.conftest import load_event

NEXT = "What else would you like the robots to do?"


def commands() -> list[tuple[str, str, dict[str, Any]]]:
    """(topic, action, params) of every command the skill published."""
    sent = [(topic, json.loads(payload)) for topic, payload in published()]
    return [(topic, body["action"], body["params"]) for topic, body in sent]


def directive(response: dict[str, Any]) -> dict[str, Any]:
    [only] = response["response"]["directives"]
    return dict(only)


def test_no_zone_b_sends_the_same_robot_to_zone_b(skill: Any, robots: Any) -> None:
    # Given placebot one was sent to zone C in this conversation
    # When the person says "no, zone b"
    response = skill(load_event("alexa_dialog_correction_zone"), None)
    # Then placebot one alone gets a navigate to B, which preempts the old one
    assert commands() == [("vahr/robots/placebot1/cmd", "navigate", {"zone": "B"})]
    assert speech(response) == "Okay, not zone C. Placebot one is on its way to zone B."
    # and the corrected command is the one a next correction refers to
    last = response["sessionAttributes"]["lastCommand"]
    assert (last["robot"], last["zone"]) == ("placebot1", "B")


def test_i_meant_placebot_two_stops_the_first_and_sends_the_second(skill: Any, robots: Any) -> None:
    response = skill(load_event("alexa_dialog_correction_robot"), None)
    assert commands() == [
        ("vahr/robots/placebot1/cmd", "stop", {}),
        ("vahr/robots/placebot2/cmd", "navigate", {"zone": "C"}),
    ]
    assert speech(response) == (
        "Okay, not placebot one. Placebot one has stopped. Placebot two is on its way to zone C."
    )


def test_cancel_that_stops_only_the_robot_the_last_command_went_to(skill: Any, robots: Any) -> None:
    response = skill(load_event("alexa_dialog_undo"), None)
    assert commands() == [("vahr/robots/placebot1/cmd", "stop", {})]
    assert speech(response) == "Okay, I cancelled that. Placebot one has stopped."
    # Nothing is left to undo a second time.
    assert "lastCommand" not in response.get("sessionAttributes", {})


def test_a_correction_or_undo_with_nothing_sent_says_so_and_sends_nothing(
    skill: Any, aws: None
) -> None:
    corrected = skill(load_event("alexa_dialog_correction_nothing_sent"), None)
    assert speech(corrected) == "There is no command of mine to correct, so I changed nothing."
    undone = skill(load_event("alexa_dialog_undo_nothing_sent"), None)
    assert speech(undone).startswith("There is no command of mine to cancel, so I changed nothing.")
    assert published() == []


def test_not_that_robot_confirms_the_other_robot_before_moving_it(skill: Any, robots: Any) -> None:
    # "Not that robot" names no robot: in a fleet of two the skill proposes the other one
    response = skill(load_event("alexa_dialog_correction_other_robot"), None)
    confirm = directive(response)
    assert confirm["type"] == "Dialog.ConfirmSlot"
    assert confirm["slotToConfirm"] == "robot"
    assert confirm["updatedIntent"]["slots"]["robot"]["value"] == "placebot two"
    assert speech(response) == reprompt(response) == "Placebot two instead?"
    assert response["response"]["shouldEndSession"] is False
    assert published() == []
    # "Yes": the slot comes back CONFIRMED, and placebot two takes placebot one's command
    confirmed = skill(load_event("alexa_dialog_confirm_slot_confirmed"), None)
    assert commands() == [
        ("vahr/robots/placebot1/cmd", "stop", {}),
        ("vahr/robots/placebot2/cmd", "navigate", {"zone": "C"}),
    ]
    assert "Placebot two is on its way to zone C." in speech(confirmed)


def test_a_denied_robot_is_asked_for_by_name(skill: Any, aws: None) -> None:
    response = skill(load_event("alexa_dialog_confirm_slot_denied"), None)
    elicit = directive(response)
    assert (elicit["type"], elicit["slotToElicit"]) == ("Dialog.ElicitSlot", "robot")
    assert speech(response) == "Which robot did you mean: placebot one or placebot two?"
    assert published() == []


def test_a_zone_heard_as_b_or_d_is_asked_about_instead_of_acted_on(skill: Any, aws: None) -> None:
    response = skill(load_event("alexa_dialog_zone_ambiguous"), None)
    elicit = directive(response)
    assert (elicit["type"], elicit["slotToElicit"]) == ("Dialog.ElicitSlot", "zone")
    assert speech(response) == "Zone B or zone D?"
    # Should the answer not be caught, the reprompt offers the letters' spelling-alphabet
    # words, which are far easier to tell apart than B and D.
    assert reprompt(response) == "Zone B or zone D? You can also say bravo or delta."
    # The robot already said is kept; the zone is asked afresh.
    assert elicit["updatedIntent"]["slots"]["robot"]["value"] == "placebot one"
    assert "value" not in elicit["updatedIntent"]["slots"]["zone"]
    assert published() == []


def test_asked_again_about_b_or_d_the_question_offers_bravo_or_delta(skill: Any, aws: None) -> None:
    # Given the skill already asked a question about this command
    event = load_event("alexa_dialog_zone_ambiguous")
    event["session"]["new"] = False
    event["session"]["attributes"] = {"questions": 1}
    # When the zone is still heard as B or D
    response = skill(event, None)
    # Then the question itself says how else to answer
    assert speech(response) == "Zone B or zone D? You can also say bravo or delta."
    assert directive(response)["slotToElicit"] == "zone"
    assert published() == []


def test_bravo_answers_the_zone_question(skill: Any, robots: Any) -> None:
    event = load_event("alexa_dialog_zone_ambiguous")
    zone = event["request"]["intent"]["slots"]["zone"]
    # "bravo", read by the skill's own vocabulary (no entity resolution given)
    zone["value"] = "bravo"
    zone.pop("resolutions")
    zone.pop("slotValue")
    response = skill(event, None)
    assert commands() == [("vahr/robots/placebot1/cmd", "navigate", {"zone": "B"})]
    assert speech(response).startswith("Placebot one is on its way to zone B.")


def test_an_answer_carrying_new_values_is_acted_on_with_them(skill: Any, robots: Any) -> None:
    response = skill(load_event("alexa_dialog_answer_replaces_zone"), None)
    assert commands() == [("vahr/robots/placebot2/cmd", "navigate", {"zone": "A"})]
    assert speech(response) == "Placebot two is on its way to zone A."


def test_a_denied_intent_sends_nothing(skill: Any, aws: None) -> None:
    response = skill(load_event("alexa_dialog_confirm_intent_denied"), None)
    assert speech(response) == "Okay, I sent nothing. Please say it again."
    assert response["response"]["shouldEndSession"] is False
    assert published() == []
