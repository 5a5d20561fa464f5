"""The experiment's weather, kept in the experiment thing's classic shadow.

The experiment runner normally writes it. When none is set, the skill draws sunny or rainy
at random and stores it, as the paper's skill randomised it per experiment, so the person,
the robots and the judge all hear the same weather. The write carries the shadow version,
so two requests racing to draw a weather end up agreeing on the first one stored.
"""

from __future__ import annotations

import random
from typing import TYPE_CHECKING

import msgspec

from skill.errors import ShadowConflict
from skill.logs import log_event
from vahr.domain import WEATHERS
from vahr.protocol import ExperimentState, experiment_state_from_payload

if TYPE_CHECKING:
    from skill.gateway import RobotGateway
    from vahr.protocol import Weather

ATTEMPTS = 3


class _Version(msgspec.Struct):
    version: int | None = None


def current_weather(gateway: RobotGateway, thing: str, rng: random.Random | None = None) -> Weather:
    """The experiment's weather; drawn and stored first when the shadow has none."""
    draw = rng or random.Random()
    for _ in range(ATTEMPTS):
        payload = gateway.get_shadow(thing)
        state = experiment_state_from_payload(payload) if payload else ExperimentState()
        if state.weather is not None:
            return state.weather
        weather = draw.choice(WEATHERS)
        version = msgspec.json.decode(payload, type=_Version).version if payload else None
        try:
            gateway.update_shadow(thing, _update(state, weather, version))
        except ShadowConflict:
            continue  # someone else wrote meanwhile: read again and use theirs if set
        log_event("weather_drawn", thing=thing, weather=weather)
        return weather
    raise ShadowConflict(f"the shadow of {thing} kept changing while storing the weather")


def _update(state: ExperimentState, weather: Weather, version: int | None) -> bytes:
    # The runner's assignments and session are written back as read, so they survive
    # whether the shadow service merges the reported state (AWS) or not.
    kept = ExperimentState(weather=weather, assignments=state.assignments, session=state.session)
    body: dict[str, object] = {"state": {"reported": kept}}
    if version is not None:
        body["version"] = version
    return msgspec.json.encode(body)
