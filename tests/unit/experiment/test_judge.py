"""The judge on hand-written session logs: every success and failure case of each task."""

from __future__ import annotations

from typing import TYPE_CHECKING

from tests.unit.experiment.conftest import plan
from vahr.experiment.judge import judge_session

if TYPE_CHECKING:
    from tests.unit.experiment.conftest import SessionScript


def verdict(script: SessionScript, weather: str = "sunny"):  # type: ignore[no-untyped-def]
    return judge_session(script.log.entries(), plan(weather))


# Task I: placebot1 -> B, placebot2 -> D


def test_task_one_succeeds_when_each_robot_delivers_to_its_zone(script: SessionScript) -> None:
    script.start("I", 0)
    script.robot(50, "placebot2", "delivered", "D")
    script.robot(60, "placebot1", "delivered", "B")
    script.end(61)
    outcome = verdict(script).tasks["I"]
    assert outcome.success is True
    assert outcome.duration_s == 61


def test_task_one_fails_when_a_robot_delivers_to_the_wrong_zone(script: SessionScript) -> None:
    script.start("I", 0)
    script.robot(50, "placebot1", "delivered", "C")
    script.robot(60, "placebot2", "delivered", "D")
    script.end(61)
    outcome = verdict(script).tasks["I"]
    assert outcome.success is False
    assert outcome.reason == "placebot1 delivered to C, not B"


def test_task_one_a_wrong_first_delivery_cannot_be_undone(script: SessionScript) -> None:
    script.start("I", 0)
    script.robot(40, "placebot2", "delivered", "A")
    script.robot(80, "placebot2", "delivered", "D")
    script.robot(90, "placebot1", "delivered", "B")
    script.end(91)
    assert verdict(script).tasks["I"].reason == "placebot2 delivered to A, not D"


def test_task_one_fails_when_a_robot_never_delivers(script: SessionScript) -> None:
    script.start("I", 0)
    script.robot(30, "placebot1", "delivered", "B")
    script.robot(40, "placebot2", "failed", reason="no path to D")
    script.end(300)
    outcome = verdict(script).tasks["I"]
    assert outcome.success is False
    assert outcome.reason == (
        "the task ended before placebot2 delivered (last: placebot2 failed: no path to D)"
    )


def test_deliveries_outside_the_task_do_not_count(script: SessionScript) -> None:
    script.robot(5, "placebot1", "delivered", "B")
    script.start("I", 10)
    script.robot(50, "placebot2", "delivered", "D")
    script.end(60)
    assert verdict(script).tasks["I"].success is False


def test_a_task_never_run_fails(script: SessionScript) -> None:
    outcome = verdict(script).tasks["II"]
    assert (outcome.success, outcome.reason) == (False, "the task was not run")


def test_an_interrupted_task_fails_with_its_own_reason(script: SessionScript) -> None:
    script.start("II", 0)
    outcome = verdict(script).tasks["II"]
    assert outcome.reason == "the task was interrupted before placebot1 delivered"
    assert outcome.duration_s is None


# Task II: sunny -> A, rainy -> C


def test_task_two_sunny_is_zone_a(script: SessionScript) -> None:
    script.start("II", 0)
    script.robot(70, "placebot1", "delivered", "A")
    script.end(71)
    assert verdict(script, "sunny").tasks["II"].success is True


def test_task_two_rainy_is_zone_c(script: SessionScript) -> None:
    script.start("II", 0)
    script.robot(70, "placebot1", "delivered", "C")
    script.end(71)
    assert verdict(script, "rainy").tasks["II"].success is True


def test_task_two_wrong_zone_is_a_failure_to_interpret_the_assistant(
    script: SessionScript,
) -> None:
    script.start("II", 0)
    script.robot(70, "placebot1", "delivered", "A")
    script.end(71)
    outcome = verdict(script, "rainy").tasks["II"]
    assert outcome.success is False
    assert outcome.reason == (
        "placebot1 delivered to A, not C; the weather was rainy: a failure to interpret the assistant"
    )


def test_task_two_ignores_the_other_robot(script: SessionScript) -> None:
    script.start("II", 0)
    script.robot(30, "placebot2", "delivered", "B")
    script.robot(70, "placebot1", "delivered", "A")
    script.end(71)
    assert verdict(script, "sunny").tasks["II"].success is True


# Task III: both to D, placebot1 first; the LED lights only on success


def test_task_three_succeeds_in_order_and_reports_the_led(script: SessionScript) -> None:
    script.start("III", 0)
    script.led(0, False)
    script.robot(60, "placebot1", "delivered", "D")
    script.robot(95, "placebot2", "delivered", "D")
    script.led(95, True)
    script.end(96)
    outcome = verdict(script).tasks["III"]
    assert (outcome.success, outcome.led_on) == (True, True)
    assert outcome.reason == "delivered to D in order placebot1, placebot2"


def test_task_three_fails_in_the_wrong_order(script: SessionScript) -> None:
    script.start("III", 0)
    script.led(0, False)
    script.robot(60, "placebot2", "delivered", "D")
    script.robot(95, "placebot1", "delivered", "D")
    script.end(96)
    outcome = verdict(script).tasks["III"]
    assert (outcome.success, outcome.led_on) == (False, False)
    assert outcome.reason == "placebot2 delivered before placebot1"


def test_task_three_fails_when_a_robot_delivers_elsewhere(script: SessionScript) -> None:
    script.start("III", 0)
    script.robot(60, "placebot1", "delivered", "D")
    script.robot(95, "placebot2", "delivered", "C")
    script.end(96)
    assert verdict(script).tasks["III"].reason == "placebot2 delivered to C, not D"


def test_task_three_fails_when_only_one_robot_delivers(script: SessionScript) -> None:
    script.start("III", 0)
    script.robot(60, "placebot1", "delivered", "D")
    script.robot(70, "placebot2", "stuck", reason="blocked by an obstacle")
    script.end(200)
    outcome = verdict(script).tasks["III"]
    assert outcome.success is False
    assert "placebot2 stuck: blocked by an obstacle" in outcome.reason


# Commands and communication


def test_command_success_needs_an_acknowledgment_and_no_failure(script: SessionScript) -> None:
    script.start("I", 0)
    script.command(1, "c1")
    script.robot(1.1, "placebot1", "accepted", command_id="c1")
    script.command(2, "c2", target="placebot2", zone="Q")
    script.robot(
        2.1, "placebot2", "rejected", command_id="c2", reason="params.zone: 'Q' is not a zone"
    )
    script.command(3, "c3", target="placebot2", zone="D")
    script.command(4, "c4", target="placebot2", zone="D")
    script.robot(4.1, "placebot2", "accepted", command_id="c4")
    script.robot(30, "placebot2", "failed", command_id="c4", reason="arm jammed")
    script.command(5, "peer", action="ping", zone=None, source="robot:placebot1")
    script.end(40)
    commands = verdict(script).commands
    assert (commands.successes, commands.total) == (1, 4)
    assert commands.failure_rate == 0.75
    assert commands.failures == (
        "deliver c2 rejected: params.zone: 'Q' is not a zone",
        "deliver c3 was never acknowledged",
        "deliver c4 failed: arm jammed",
    )


def test_communication_counts_understood_utterances_and_robot_exchanges(
    script: SessionScript,
) -> None:
    script.start("II", 0)
    script.interact(0, 5, commands=["c1"])
    script.interact(6, 9, commands=[], text="placebot do the thing")
    script.interact(10, 12, commands=[], error="the assistant did not answer")
    script.robot(20, "placebot1", "interpreted", text="the weather is sunny", intent="sunny")
    script.robot(25, "placebot2", "interpreted", text="mumble", intent="unknown")
    script.end(30)
    communication = verdict(script).communication
    assert (communication.successes, communication.total) == (2, 5)
    assert communication.failures == (
        "'placebot do the thing': no command resulted",
        "'tell placebot one to deliver to zone b': the assistant did not answer",
        "placebot2 did not understand 'mumble'",
    )


def test_task_rates_count_every_planned_task(script: SessionScript) -> None:
    script.start("I", 0)
    script.robot(50, "placebot2", "delivered", "D")
    script.robot(60, "placebot1", "delivered", "B")
    script.end(61)
    tally = verdict(script).task_tally
    assert (tally.successes, tally.total) == (1, 3)
    assert verdict(script).to_json()["task_success"]["success_rate"] == 1 / 3


def test_a_robot_finishing_an_earlier_tasks_command_does_not_count(script: SessionScript) -> None:
    # Given task I, where placebot2 is still driving to C for a command of the previous session
    script.robot(0, "placebot2", "accepted", command_id="old")
    script.start("I", 1)
    script.command(2, "c1", zone="B")
    script.command(3, "c2", target="placebot2", zone="D")
    script.robot(20, "placebot2", "delivered", "C", command_id="old")
    script.robot(50, "placebot1", "delivered", "B", command_id="c1")
    script.robot(60, "placebot2", "delivered", "D", command_id="c2")
    script.end(61)
    # Then only the deliveries of task I's own commands are judged
    outcome = verdict(script).tasks["I"]
    assert outcome.success is True, outcome.reason
    assert [(d.thing, d.zone) for d in outcome.deliveries] == [
        ("placebot1", "B"),
        ("placebot2", "D"),
    ]
