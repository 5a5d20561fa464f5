"""Every intent end to end under moto: the message on the wire and the words spoken.

Robot doubles answer through their shadows while the handler waits, as robot-agent would.
"""

from __future__ import annotations

import json
import time
from typing import TYPE_CHECKING, Any

import pytest
from skill_testkit import RobotBehaviour, check_response, published, reprompt, speech

from tests.conftest import load_event
from vahr.protocol import decode_command

if TYPE_CHECKING:
    from skill_testkit import RobotDoubles

    from vahr.domain import Fleet


def commands_sent(fleet: Fleet) -> list[tuple[str, dict[str, Any]]]:
    """(topic, JSON) of every command published, each checked against the wire contract."""
    sent = []
    for topic, payload in published():
        decode_command(payload, fleet)
        sent.append((topic, json.loads(payload)))
    return sent


@pytest.mark.parametrize(
    ("event", "topic", "action", "params", "spoken"),
    [
        (
            "alexa_navigate",
            "vahr/robots/placebot1/cmd",
            "navigate",
            {"zone": "A"},
            "Placebot one is on its way to zone A.",
        ),
        (
            "alexa_deliver",
            "vahr/robots/placebot1/cmd",
            "deliver",
            {"zone": "B"},
            "Placebot one is on its way to pick up a package for zone B.",
        ),
        (
            "alexa_weather_delivery",
            "vahr/robots/placebot2/cmd",
            "weather_delivery",
            {},
            "Placebot two will ask me about the weather and deliver accordingly.",
        ),
        (
            "alexa_emergency_stop_robot",
            "vahr/robots/placebot2/cmd",
            "stop",
            {},
            "Placebot two has stopped.",
        ),
        (
            "alexa_navigate_unresolved_values",
            "vahr/robots/placebot1/cmd",
            "navigate",
            {"zone": "C"},
            "Placebot one is on its way to zone C.",
        ),
    ],
)
def test_one_robot_command_is_published_and_acknowledged(
    skill: Any,
    robots: RobotDoubles,
    fleet: Fleet,
    event: str,
    topic: str,
    action: str,
    params: dict[str, Any],
    spoken: str,
) -> None:
    # Given robots that acknowledge 0.2 s after a command arrives
    # When the person speaks a one-shot command
    response = skill(load_event(event), None)
    # Then one command went to that robot's topic with QoS 1, and the skill says it is under way
    [(sent_topic, command)] = commands_sent(fleet)
    assert sent_topic == topic
    assert command["action"] == action
    assert command["params"] == params
    assert command["source"] == "alexa"
    assert speech(response) == spoken
    assert response["response"]["shouldEndSession"] is True


def test_fleet_command_is_published_once_and_every_robot_confirms(
    skill: Any, robots: RobotDoubles, fleet: Fleet
) -> None:
    # Given both robots online
    # When the person sends all robots to the loading zone
    response = skill(load_event("alexa_navigate_fleet"), None)
    # Then one publish on the fleet topic, both robots report its id, and the skill says so
    [(topic, command)] = commands_sent(fleet)
    assert topic == "vahr/fleet/cmd"
    assert command["action"] == "navigate" and command["params"] == {"zone": "LOADING"}
    assert sorted(thing for thing, command_id, _ in robots.answered) == ["placebot1", "placebot2"]
    assert {command_id for _, command_id, _ in robots.answered} == {command["id"]}
    assert speech(response) == "Both robots are on their way to the loading zone."


def test_emergency_stop_without_a_robot_stops_the_whole_fleet(
    skill: Any, robots: RobotDoubles, fleet: Fleet
) -> None:
    response = skill(load_event("alexa_emergency_stop"), None)
    [(topic, command)] = commands_sent(fleet)
    assert (topic, command["action"]) == ("vahr/fleet/cmd", "stop")
    assert speech(response) == "Both robots have stopped."


@pytest.mark.parametrize("values", [[None, "placebot2"], [None]], ids=["beside", "alone"])
def test_a_resolution_holding_a_null_value_is_passed_over(
    skill: Any, robots: RobotDoubles, fleet: Fleet, values: list[str | None]
) -> None:
    # Given "stop placebot two" whose resolution came with a null entry (the fuzz test's find)
    event = load_event("alexa_emergency_stop_robot")
    resolution = event["request"]["intent"]["slots"]["robot"]["resolutions"]
    resolution["resolutionsPerAuthority"][0]["values"] = [
        value and {"value": {"name": "placebot two", "id": value}} for value in values
    ]
    response = skill(event, None)
    # Then the skill answers with valid speech: beside a real value the null one is passed
    # over and placebot two stops; alone, the name did not resolve and is asked about
    check_response(response)
    sent = commands_sent(fleet)
    if values == [None]:
        assert sent == [] and "Which robot" in speech(response)
    else:
        assert [(topic, command["action"]) for topic, command in sent] == [
            ("vahr/robots/placebot2/cmd", "stop")
        ]


def test_sequential_delivery_sends_the_second_robot_after_the_first(
    skill: Any, robots: RobotDoubles, fleet: Fleet
) -> None:
    response = skill(load_event("alexa_sequential_delivery"), None)
    sent = commands_sent(fleet)
    assert [(topic, command["action"], command["params"]) for topic, command in sent] == [
        ("vahr/robots/placebot1/cmd", "sequential_delivery", {"zone": "A", "after": None}),
        ("vahr/robots/placebot2/cmd", "sequential_delivery", {"zone": "B", "after": "placebot1"}),
    ]
    assert speech(response) == (
        "Placebot one will deliver to zone A, then placebot two will deliver to zone B."
    )


def test_sequential_delivery_with_two_robots_infers_the_other_one(
    skill: Any, robots: RobotDoubles, fleet: Fleet
) -> None:
    # Given "robot two delivers to delta, then the other one to zone c" (no second robot named)
    response = skill(load_event("alexa_sequential_delivery_other_robot"), None)
    sent = commands_sent(fleet)
    assert [(topic, command["params"]) for topic, command in sent] == [
        ("vahr/robots/placebot2/cmd", {"zone": "D", "after": None}),
        ("vahr/robots/placebot1/cmd", {"zone": "C", "after": "placebot2"}),
    ]
    assert speech(response).startswith("Placebot two will deliver to zone D, then placebot one")


def test_status_speaks_every_robot_from_its_shadow(
    skill: Any, iot_data: Any, robots: RobotDoubles
) -> None:
    # Given placebot one carrying a package to B and placebot two idle in the loading zone
    from vahr.protocol import Reported

    robots.report(
        "placebot1",
        Reported(status="navigating", cargo=True, destination="B", task="deliver", connected=True),
    )
    robots.report("placebot2", Reported(status="idle", zone="LOADING", connected=True))
    # When the person asks what the robots are doing
    response = skill(load_event("alexa_status"), None)
    # Then nothing is published and both robots are described
    assert published() == []
    assert speech(response) == (
        "Placebot one is carrying a package to zone B. Placebot two is idle in the loading zone."
    )


def test_status_of_one_robot(skill: Any, robots: RobotDoubles) -> None:
    from vahr.protocol import Reported

    robots.report("placebot1", Reported(status="stuck", destination="D", connected=True))
    response = skill(load_event("alexa_status_robot"), None)
    assert speech(response) == "Placebot one is stuck on its way to zone D."


def test_status_of_a_robot_that_never_reported(skill: Any, aws: None) -> None:
    response = skill(load_event("alexa_status"), None)
    assert (
        speech(response) == "Placebot one has not reported yet. Placebot two has not reported yet."
    )


def test_launch_opens_a_conversation_that_later_answers_keep_open(
    skill: Any, robots: RobotDoubles
) -> None:
    launch = skill(load_event("alexa_launch"), None)
    assert launch["response"]["shouldEndSession"] is False
    assert launch["sessionAttributes"] == {"conversation": True}
    assert "send placebot one to zone A" in reprompt(launch)
    # A command inside that session answers and asks what is next.
    response = skill(load_event("alexa_navigate_in_conversation"), None)
    assert speech(response) == (
        "Placebot two is on its way to zone B. What else would you like the robots to do?"
    )
    assert response["response"]["shouldEndSession"] is False


@pytest.mark.parametrize(
    ("event", "spoken", "ends"),
    [
        ("alexa_help", "You can say: send placebot one to zone A;", False),
        ("alexa_cancel", "Goodbye. The robots carry on; to halt them, say emergency stop.", True),
        ("alexa_stop", "Goodbye. The robots carry on; to halt them, say emergency stop.", True),
        ("alexa_navigate_home", "Goodbye.", True),
        ("alexa_fallback", "Sorry, robot fleet can't help with that.", False),
    ],
)
def test_built_in_intents(skill: Any, aws: None, event: str, spoken: str, ends: bool) -> None:
    response = skill(load_event(event), None)
    assert speech(response).startswith(spoken)
    assert response["response"]["shouldEndSession"] is ends
    assert published() == []


def test_session_ended_request_returns_an_empty_response(skill: Any, aws: None) -> None:
    response = skill(load_event("alexa_session_ended"), None)
    check_response(response)
    assert "outputSpeech" not in response["response"]
    assert published() == []


def test_the_module_level_lambda_handler_serves_requests(
    robots: RobotDoubles, fleet: Fleet
) -> None:
    # Given only AWS_DEFAULT_REGION configured (the `aws` fixture) and the defaults for the rest
    import skill.app

    # When Lambda calls the module-level entry point
    started = time.perf_counter()
    response = skill.app.lambda_handler(load_event("alexa_navigate"), None)
    # Then it publishes, waits for the acknowledgment and answers well inside Alexa's 8 s
    assert time.perf_counter() - started < 2.5
    assert [topic for topic, _ in commands_sent(fleet)] == ["vahr/robots/placebot1/cmd"]
    assert speech(response) == "Placebot one is on its way to zone A."


def test_concurrent_requests_do_not_mix_their_answers(skill: Any, robots: RobotDoubles) -> None:
    # Given one handler serving several people at once (the local simulator may do this)
    from concurrent.futures import ThreadPoolExecutor

    from vahr.protocol import Reported

    robots.behave(
        "placebot2",
        RobotBehaviour(
            reported=lambda _: Reported(status="waiting", task="weather_delivery", connected=True)
        ),
    )
    events = ["alexa_navigate", "alexa_weather_delivery", "alexa_weather", "alexa_status_robot"]
    # When a command to each robot, a weather question and a status question arrive together
    with ThreadPoolExecutor(max_workers=4) as pool:
        spoken = list(pool.map(lambda name: speech(skill(load_event(name), None)), events))
    # Then each request got its own answer
    assert spoken[0] == "Placebot one is on its way to zone A."
    assert spoken[1] == "Placebot two will ask me about the weather and deliver accordingly."
    assert spoken[2] in ("The weather is sunny.", "The weather is rainy.")
    assert spoken[3].startswith("Placebot one is ")
