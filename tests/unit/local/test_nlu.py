"""The NLU built from skill-package/: intents, slots and entity resolution as Alexa gives them."""

from __future__ import annotations

import pytest

from vahr.local.alexa import envelope
from vahr.local.alexa.nlu import InteractionModel
from vahr.local.alexa.simulator import strip_invocation


@pytest.fixture(scope="module")
def model() -> InteractionModel:
    return InteractionModel.load()


@pytest.mark.parametrize(
    ("utterance", "intent", "slots"),
    [
        ("send robot one to zone b", "NavigateIntent", {"robot": "placebot1", "zone": "B"}),
        ("Send everyone to the loading zone!", "NavigateIntent", {"robot": "all", "zone": "LOADING"}),
        ("where is placebot two", "StatusIntent", {"robot": "placebot2"}),
        ("have placebot 1 deliver a package to zone c", "DeliverIntent",
         {"robot": "placebot1", "zone": "C"}),
        ("robot one deliver to zone a then robot two deliver to zone c",
         "SequentialDeliveryIntent",
         {"firstRobot": "placebot1", "firstZone": "A", "secondRobot": "placebot2",
          "secondZone": "C"}),
        ("have robot one deliver based on the weather", "WeatherDeliveryIntent",
         {"robot": "placebot1"}),
        ("emergency stop", "EmergencyStopIntent", {}),
        ("help", "AMAZON.HelpIntent", {}),
        ("stop", "AMAZON.StopIntent", {}),
        ("cancel", "AMAZON.CancelIntent", {}),
        ("make me a sandwich", "AMAZON.FallbackIntent", {}),
    ],
)  # fmt: skip
def test_utterances_resolve_to_intents_and_slot_ids(
    model: InteractionModel, utterance: str, intent: str, slots: dict[str, str]
) -> None:
    understood = model.understand(utterance)
    assert understood.intent == intent
    assert {name: value.id for name, value in understood.slots.items()} == slots


def test_an_unknown_value_fills_the_slot_without_an_id(model: InteractionModel) -> None:
    understood = model.understand("send robot nine to zone b")
    assert understood.intent == "NavigateIntent"
    robot = understood.slots["robot"]
    assert (robot.spoken, robot.id) == ("robot nine", None)


def test_the_invocation_is_removed_from_one_shot_requests(model: InteractionModel) -> None:
    name = model.invocation_name
    assert strip_invocation(name, "Alexa, ask robot fleet to send robot one to A") == (
        "send robot one to a"
    )
    assert strip_invocation(name, "alexa tell robot fleet where is robot two") == (
        "where is robot two"
    )
    assert strip_invocation(name, "where is robot two") == "where is robot two"


def test_the_envelope_carries_alexa_resolutions(model: InteractionModel) -> None:
    identity = envelope.Identity("amzn1.ask.skill.test")
    understood = model.understand("send robot nine to zone b")
    request = envelope.intent_request(identity, understood, "STARTED")
    event = envelope.envelope(identity, request, session_id="s1", new=True, attributes={"a": 1})
    assert event["session"]["attributes"] == {"a": 1}
    assert event["context"]["System"]["application"]["applicationId"] == "amzn1.ask.skill.test"
    slots = event["request"]["intent"]["slots"]
    zone = slots["zone"]["resolutions"]["resolutionsPerAuthority"][0]
    assert zone["authority"] == "amzn1.er-authority.echo-sdk.amzn1.ask.skill.test.ZONE"
    assert zone["status"] == {"code": "ER_SUCCESS_MATCH"}
    assert zone["values"] == [{"value": {"name": "zone b", "id": "B"}}]
    robot = slots["robot"]["resolutions"]["resolutionsPerAuthority"][0]
    assert robot["status"] == {"code": "ER_SUCCESS_NO_MATCH"}
    assert event["request"]["dialogState"] == "STARTED"
