"""The acknowledgment wait: a robot's shadow update arriving while the handler waits,
rejections, silence, offline robots, partial fleet answers, and concurrent shadow reads."""

from __future__ import annotations

import json
import time
from typing import TYPE_CHECKING, Any

from skill_testkit import RobotBehaviour, published, speech

from skill.acknowledgment import await_acknowledgments
from skill.iot_data import IotDataGateway
from tests.conftest import load_event
from vahr.protocol import Reported

if TYPE_CHECKING:
    from skill_testkit import RobotDoubles


def sent_id() -> str:
    [(_, payload)] = published()
    command_id: str = json.loads(payload)["id"]
    return command_id


def test_acknowledgment_that_arrives_during_the_wait_is_spoken(
    make_skill: Any, robots: RobotDoubles
) -> None:
    # Given a robot that writes its shadow 0.6 s after the command reaches it
    robots.behave("placebot1", RobotBehaviour(delay_s=0.6))
    skill = make_skill(ack_timeout_s=2.5)
    # When the person sends it to zone A
    started = time.monotonic()
    response = skill(load_event("alexa_navigate"), None)
    answered_at = time.monotonic()
    # Then the shadow update came from the robot while the handler was waiting...
    [(thing, command_id, reported_at)] = robots.answered
    assert (thing, command_id) == ("placebot1", sent_id())
    assert started + 0.6 <= reported_at <= answered_at
    # ...and the skill answered soon after it, not at the end of the budget
    assert answered_at - reported_at < 0.6
    assert speech(response) == "Placebot one is on its way to zone A."


def test_rejected_command_speaks_the_robots_reason(make_skill: Any, robots: RobotDoubles) -> None:
    robots.behave(
        "placebot1",
        RobotBehaviour(result="rejected", reason="params.zone: 'A' is blocked by an obstacle"),
    )
    response = make_skill()(load_event("alexa_navigate"), None)
    # The zone the reason names by id is said by its name.
    assert speech(response) == (
        "Placebot one refused the command: params.zone: 'zone A' is blocked by an obstacle."
    )


def test_failed_command_speaks_the_reason(make_skill: Any, robots: RobotDoubles) -> None:
    robots.behave("placebot1", RobotBehaviour(result="failed", reason="no path to zone A."))
    response = make_skill()(load_event("alexa_navigate"), None)
    assert speech(response) == "Placebot one could not do it: no path to zone A."


def test_not_confirmed_by_an_offline_robot(make_skill: Any, robots: RobotDoubles) -> None:
    # Given placebot two's last will marked it disconnected, and it never answers
    robots.behave("placebot2", RobotBehaviour(result=None))
    robots.report("placebot2", Reported(status="idle", zone="B", connected=False))
    skill = make_skill(ack_timeout_s=0.5)
    # When the person sends it somewhere
    started = time.monotonic()
    response = skill(load_event("alexa_navigate_in_conversation"), None)
    # Then the command was still published, and the skill says the robot seems offline after
    # the budget, not much later
    assert [topic for topic, _ in published()] == ["vahr/robots/placebot2/cmd"]
    assert 0.5 <= time.monotonic() - started < 1.5
    assert speech(response).startswith("I sent the command, but placebot two seems to be offline.")


def test_not_confirmed_by_a_connected_robot(make_skill: Any, robots: RobotDoubles) -> None:
    robots.behave("placebot1", RobotBehaviour(result=None))
    response = make_skill(ack_timeout_s=0.4)(load_event("alexa_navigate"), None)
    assert speech(response) == "I sent the command, but placebot one did not confirm it in time."


def test_robot_without_a_shadow_counts_as_offline(make_skill: Any, aws: None) -> None:
    # Given robots that have never connected (no shadow at all)
    response = make_skill(ack_timeout_s=0.3)(load_event("alexa_navigate"), None)
    assert speech(response) == "I sent the command, but placebot one seems to be offline."


def test_fleet_with_one_robot_silent(make_skill: Any, robots: RobotDoubles) -> None:
    # Given placebot two is offline and never answers
    robots.behave("placebot2", RobotBehaviour(result=None))
    robots.report("placebot2", Reported(status="idle", zone="LOADING", connected=False))
    response = make_skill(ack_timeout_s=0.6)(load_event("alexa_navigate_fleet"), None)
    assert speech(response) == (
        "1 of 2 robots confirmed; placebot two did not answer and seems to be offline."
    )


def test_fleet_with_one_robot_refusing(make_skill: Any, robots: RobotDoubles) -> None:
    robots.behave("placebot1", RobotBehaviour(result="rejected", reason="battery low"))
    response = make_skill()(load_event("alexa_emergency_stop"), None)
    assert speech(response) == "1 of 2 robots confirmed; placebot one refused: battery low."


def test_fleet_with_no_robot_answering(make_skill: Any, robots: RobotDoubles) -> None:
    robots.behave("placebot1", RobotBehaviour(result=None))
    robots.behave("placebot2", RobotBehaviour(result=None))
    response = make_skill(ack_timeout_s=0.3)(load_event("alexa_navigate_fleet"), None)
    assert speech(response) == (
        "None of the 2 robots confirmed; placebot one had not answered yet; placebot two had not answered yet."
    )


def test_shadows_of_several_robots_are_read_concurrently(
    iot_data: Any, robots: RobotDoubles
) -> None:
    # Given a gateway whose every shadow read takes 0.5 s
    class SlowGateway(IotDataGateway):
        def get_shadow(self, thing: str) -> bytes | None:
            time.sleep(0.5)
            return super().get_shadow(thing)

    gateway = SlowGateway(iot_data)
    for thing in ("placebot1", "placebot2"):
        robots.behave(thing, RobotBehaviour(result=None))
        robots.report(thing, Reported(connected=True))
    # When the skill waits for two robots that never answer, with a 0.4 s budget
    started = time.monotonic()
    answers = await_acknowledgments(gateway, {"placebot1": "c1", "placebot2": "c1"}, 0.4)
    # Then both were read at once: about one slow read, not two one after the other
    assert time.monotonic() - started < 0.9
    assert {thing: answer.outcome for thing, answer in answers.items()} == {
        "placebot1": "unconfirmed",
        "placebot2": "unconfirmed",
    }
    assert all(answer.shadow is not None for answer in answers.values())


def test_a_reader_that_breaks_is_logged_and_counts_as_unconfirmed(
    iot_data: Any, caplog: Any
) -> None:
    class Exploding(IotDataGateway):
        def get_shadow(self, thing: str) -> bytes | None:
            raise RuntimeError("socket closed")

    answers = await_acknowledgments(Exploding(iot_data), {"placebot1": "c9"}, 0.3)
    assert answers["placebot1"].outcome == "unconfirmed"
    assert answers["placebot1"].error == "RuntimeError: socket closed"
    assert '"event": "acknowledgment_worker_failed"' in caplog.text


def test_a_reason_with_markup_characters_is_spoken_as_text(
    make_skill: Any, robots: RobotDoubles
) -> None:
    robots.behave("placebot1", RobotBehaviour(result="rejected", reason="speed <0.1 & >2 m/s"))
    response = make_skill()(load_event("alexa_navigate"), None)
    ssml = response["response"]["outputSpeech"]["ssml"]
    assert ssml == (
        "<speak>Placebot one refused the command: speed &lt;0.1 &amp; &gt;2 m/s.</speak>"
    )


def test_a_slow_publish_shortens_the_wait_so_alexa_still_gets_an_answer(
    iot_data: Any, robots: RobotDoubles, fleet: Any
) -> None:
    # Given a publish that takes 0.4 s, a 2.5 s acknowledgment budget, 0.6 s for the whole reply
    from skill.commands import publication
    from skill.robots import Robots

    class SlowPublish(IotDataGateway):
        def publish(self, topic: str, payload: bytes) -> None:
            time.sleep(0.4)
            super().publish(topic, payload)

    robots.behave("placebot1", RobotBehaviour(result=None))
    sender = Robots(SlowPublish(iot_data), ack_timeout_s=2.5, reply_budget_s=0.6)
    # When a command is sent to a robot that never answers
    started = time.monotonic()
    answers = sender.send([publication(fleet, "navigate", "placebot1", {"zone": "A"})])
    # Then the wait only used what was left of the reply budget
    assert time.monotonic() - started < 1.0
    assert answers["placebot1"].outcome == "unconfirmed"


def test_a_silent_robot_is_read_a_handful_of_times_not_continuously(
    iot_data: Any, robots: RobotDoubles
) -> None:
    # Given a robot that never answers, and a gateway that counts shadow reads (each billed)
    class Counting(IotDataGateway):
        reads = 0

        def get_shadow(self, thing: str) -> bytes | None:
            Counting.reads += 1
            return super().get_shadow(thing)

    # When the skill waits one second for it
    answers = await_acknowledgments(Counting(iot_data), {"placebot1": "c5"}, 1.0)
    # Then it read at 50, 150, 350 and 750 ms and at the deadline: five reads at most (fewer
    # when reads are slow on a busy machine)
    assert answers["placebot1"].outcome == "unconfirmed"
    assert 3 <= Counting.reads <= 5


def test_a_robot_reporting_an_unknown_status_is_still_heard_acknowledging(
    make_skill: Any, robots: RobotDoubles
) -> None:
    # Given a newer robot that reports a status this skill does not know ("charging")
    charging = Reported(status="charging", connected=True)  # type: ignore[arg-type]
    robots.behave("placebot1", RobotBehaviour(reported=lambda _: charging))
    # When it is sent somewhere
    response = make_skill()(load_event("alexa_navigate"), None)
    # Then its acknowledgment counts all the same
    assert speech(response) == "Placebot one is on its way to zone A."
