"""The experiment's weather: read from the experiment thing's shadow, or drawn and stored."""

from __future__ import annotations

import json
import random
from typing import Any

import pytest
from skill_testkit import published, speech

from skill.errors import ShadowConflict
from skill.experiment_weather import current_weather
from skill.iot_data import IotDataGateway
from tests.conftest import load_event
from vahr.protocol import ExperimentState, experiment_state_from_payload

THING = "vahr-experiment"


def stored(iot_data: Any) -> ExperimentState:
    payload = iot_data.get_thing_shadow(thingName=THING)["payload"].read()
    return experiment_state_from_payload(payload)


@pytest.mark.parametrize("weather", ["sunny", "rainy"])
def test_weather_set_by_the_experiment_runner_is_spoken(
    skill: Any, iot_data: Any, weather: str
) -> None:
    # Given the runner stored the weather and zone assignments
    state = ExperimentState(weather=weather, assignments={"placebot1": "A"}, session="s1")  # type: ignore[arg-type]
    iot_data.update_thing_shadow(thingName=THING, payload=state.to_payload())
    # When anyone asks for the weather
    response = skill(load_event("alexa_weather"), None)
    # Then the answer is the robots' sentence, and the shadow is left alone
    assert speech(response) == f"The weather is {weather}."
    assert stored(iot_data) == state
    assert published() == []


def test_weather_is_drawn_and_stored_when_none_is_set(skill: Any, iot_data: Any) -> None:
    # Given the runner stored assignments but no weather
    before = ExperimentState(assignments={"placebot1": "B", "placebot2": "D"}, session="s2")
    iot_data.update_thing_shadow(thingName=THING, payload=before.to_payload())
    # When the weather is asked twice
    first = speech(skill(load_event("alexa_weather"), None))
    second = speech(skill(load_event("alexa_weather"), None))
    # Then one weather was drawn, stored beside the assignments, and answered both times
    after = stored(iot_data)
    assert after.weather in ("sunny", "rainy")
    assert first == second == f"The weather is {after.weather}."
    assert after.assignments == before.assignments and after.session == "s2"


def test_weather_is_drawn_when_the_experiment_thing_has_no_shadow(
    skill: Any, iot_data: Any
) -> None:
    answer = speech(skill(load_event("alexa_weather"), None))
    assert answer == f"The weather is {stored(iot_data).weather}."


def test_both_weathers_can_be_drawn(iot_data: Any) -> None:
    gateway = IotDataGateway(iot_data)
    drawn = set()
    for seed in range(20):
        iot_data.delete_thing_shadow(thingName=THING) if seed else None
        drawn.add(current_weather(gateway, THING, random.Random(seed)))
    assert drawn == {"sunny", "rainy"}


def test_a_weather_stored_meanwhile_by_someone_else_wins(iot_data: Any) -> None:
    # Given another writer stores "rainy" between this skill's read and its write
    iot_data.update_thing_shadow(
        thingName=THING, payload=ExperimentState(session="s3").to_payload()
    )

    class RacingGateway(IotDataGateway):
        raced = False

        def update_shadow(self, thing: str, payload: bytes) -> bytes:
            if not self.raced:
                self.raced = True
                iot_data.update_thing_shadow(
                    thingName=thing, payload=ExperimentState(weather="rainy").to_payload()
                )
            assert "version" in json.loads(payload)
            return super().update_shadow(thing, payload)

    # When the skill draws a weather (the stale version makes its write conflict)
    weather = current_weather(RacingGateway(iot_data), THING, random.Random(0))
    # Then it answers the weather the other writer stored
    assert weather == "rainy" == stored(iot_data).weather


def test_a_shadow_that_never_settles_is_an_error(iot_data: Any) -> None:
    class ConflictingGateway(IotDataGateway):
        def update_shadow(self, thing: str, payload: bytes) -> bytes:
            raise ShadowConflict("the shadow changed meanwhile")

    with pytest.raises(ShadowConflict, match="kept changing"):
        current_weather(ConflictingGateway(iot_data), THING, random.Random(0))
