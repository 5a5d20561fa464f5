"""The world: arms load and unload, and task III's LED lights only on success."""

from __future__ import annotations

from typing import TYPE_CHECKING

from vahr.experiment.tasks import TaskGoal
from vahr.experiment.world import World

if TYPE_CHECKING:
    from pathlib import Path

    from vahr.domain import Fleet

TASK_III = TaskGoal("III", {"placebot1": "D", "placebot2": "D"}, ("placebot1", "placebot2"))


def delivered(thing: str, zone: str) -> dict[str, str]:
    return {"event": "delivered", "thing": thing, "zone": zone}


def test_the_world_has_the_fleets_arms(fleet: Fleet) -> None:
    world = World.from_fleet(fleet)
    assert world.arms["LOADING"].role == "loader"
    assert sorted(z for z, arm in world.arms.items() if arm.role == "unloader") == list("ABCD")
    assert world.led_on is False


def test_loading_and_unloading_move_the_package(fleet: Fleet) -> None:
    world = World.from_fleet(fleet)
    changes = world.apply({"event": "loaded", "thing": "placebot1", "zone": "LOADING"})
    assert changes == [{"what": "loaded", "thing": "placebot1", "zone": "LOADING", "arm": "loader"}]
    assert world.cargo["placebot1"] is True
    world.apply(delivered("placebot1", "B"))
    assert world.cargo["placebot1"] is False
    assert world.snapshot()["packages"]["B"] == ["placebot1"]
    assert world.arms["B"].handled == 1


def test_the_led_lights_when_both_deliver_to_d_in_order(fleet: Fleet) -> None:
    world = World.from_fleet(fleet)
    assert world.arm_led(TASK_III)[0]["on"] is False
    assert not any(c["what"] == "led" for c in world.apply(delivered("placebot1", "D")))
    changes = world.apply(delivered("placebot2", "D"))
    assert {
        "what": "led",
        "on": True,
        "why": "delivered to D in order placebot1, placebot2",
    } in changes
    assert world.led_on is True


def test_the_led_stays_off_in_the_wrong_order(fleet: Fleet) -> None:
    world = World.from_fleet(fleet)
    world.arm_led(TASK_III)
    world.apply(delivered("placebot2", "D"))
    world.apply(delivered("placebot1", "D"))
    assert world.led_on is False


def test_the_led_stays_off_when_a_robot_goes_elsewhere(fleet: Fleet) -> None:
    world = World.from_fleet(fleet)
    world.arm_led(TASK_III)
    world.apply(delivered("placebot1", "D"))
    world.apply(delivered("placebot2", "A"))
    world.apply(delivered("placebot2", "D"))
    assert world.led_on is False


def test_deliveries_before_task_three_do_not_light_the_led(fleet: Fleet) -> None:
    world = World.from_fleet(fleet)
    world.apply(delivered("placebot1", "D"))
    world.arm_led(TASK_III)
    world.apply(delivered("placebot2", "D"))
    assert world.led_on is False


def test_a_resumed_session_rebuilds_the_world_from_its_log(fleet: Fleet, tmp_path: Path) -> None:
    from vahr.experiment.eventlog import EventLog, Kind
    from vahr.experiment.session import OpenSession, SessionSpec, rebuild_world
    from vahr.experiment.tasks import draw_plan

    spec = SessionSpec(participant="P1", method="vahr", trial=1, seed=1, log_dir=tmp_path)
    with EventLog.open(spec.path) as log:
        log.append(Kind.ROBOT_EVENT, delivered("placebot1", "D"))
        log.append(Kind.ROBOT_EVENT, delivered("placebot2", "D"))
        log.append(Kind.WORLD, {"what": "led", "on": True})
        world = rebuild_world(fleet, OpenSession(spec, log, draw_plan(fleet, 1), resumed=True))
    assert world.led_on is True
    assert world.snapshot()["packages"]["D"] == ["placebot1", "placebot2"]


def test_an_earlier_tasks_delivery_is_unloaded_but_does_not_light_the_led(fleet: Fleet) -> None:
    world = World.from_fleet(fleet)
    world.arm_led(TASK_III)
    world.apply(delivered("placebot1", "D"))
    changes = world.apply(delivered("placebot2", "D"), for_task=False)
    assert [c["what"] for c in changes] == ["unloaded"]
    assert world.led_on is False
    assert world.snapshot()["packages"]["D"] == ["placebot1", "placebot2"]
