"""The weather delivery's rule said aloud: the skill sends the robot only when the zones the
person named are the ones robots deliver to (A when sunny, C when rainy), and otherwise says
so and sends nothing."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import pytest
from skill_testkit import check_response, published, speech

from tests.conftest import load_event
from vahr.protocol import decode_command

if TYPE_CHECKING:
    from skill_testkit import RobotDoubles

ZONE_AUTHORITY = (
    "amzn1.er-authority.echo-sdk.amzn1.ask.skill.8b5f1c1e-3f0a-4c55-9a57-2f3d6f1e9a10.ZONE"
)


def with_zones(**zones: str | None) -> dict[str, Any]:
    """The weather-delivery request for placebot two with rule zones as Alexa fills them:
    slot name -> the zone's id, or None for words that matched no zone."""
    request = load_event("alexa_weather_delivery")
    slots = request["request"]["intent"]["slots"]
    for name, zone_id in zones.items():
        spoken = f"zone {zone_id.lower()}" if zone_id else "zone q"
        status = {"code": "ER_SUCCESS_MATCH" if zone_id else "ER_SUCCESS_NO_MATCH"}
        values = [{"value": {"name": spoken, "id": zone_id}}] if zone_id else []
        slots[name] = {
            "name": name,
            "value": spoken,
            "confirmationStatus": "NONE",
            "source": "USER",
            "resolutions": {
                "resolutionsPerAuthority": [
                    {"authority": ZONE_AUTHORITY, "status": status, "values": values}
                ]
            },
        }
    return request


@pytest.mark.parametrize(
    "zones",
    [{"sunnyZone": "A", "rainyZone": "C"}, {"sunnyZone": "A"}, {"rainyZone": "C"}],
)
def test_the_rule_robots_follow_sends_the_robot(
    skill: Any, robots: RobotDoubles, zones: dict[str, str]
) -> None:
    # Given a person who says the rule as it is ("zone a if it's sunny, zone c if rainy")
    response = skill(with_zones(**zones), None)
    # Then placebot two is sent on the weather delivery
    [(topic, payload)] = published()
    assert topic == "vahr/robots/placebot2/cmd"
    assert decode_command(payload).action == "weather_delivery"
    assert speech(response) == "Placebot two will ask me about the weather and deliver accordingly."


@pytest.mark.parametrize(
    "zones",
    [
        {"sunnyZone": "B", "rainyZone": "D"},
        {"sunnyZone": "C", "rainyZone": "A"},
        {"sunnyZone": "A", "rainyZone": "A"},
        {"rainyZone": "D"},
        {"sunnyZone": None, "rainyZone": "C"},
    ],
)
def test_another_rule_sends_nothing_and_says_the_rule(
    skill: Any, robots: RobotDoubles, zones: dict[str, str | None]
) -> None:
    # Given a person who asks for a rule robots do not follow, or a zone nobody knows
    response = skill(with_zones(**zones), None)
    # Then no robot moves, and the skill says which rule weather deliveries follow
    assert published() == []
    check_response(response)
    assert speech(response) == (
        "Weather deliveries always go to zone A when it is sunny and zone C when it is rainy, "
        "so I sent no robot. For that rule, say: have placebot one deliver based on the weather."
    )
