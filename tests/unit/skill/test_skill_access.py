"""The action kinds, decided from the intent and its slots alone, and what each role may do
with them (pure: no AWS)."""

from __future__ import annotations

from typing import TYPE_CHECKING

import pytest
from ask_sdk_model import Intent, Slot
from ask_sdk_model.slu.entityresolution import (
    Resolution,
    Resolutions,
    Status,
    StatusCode,
    Value,
    ValueWrapper,
)

from skill.access import INTENT_RULES, classify, robots_asked_for
from skill.vocabulary import Vocabulary
from tests.support.fleets import SIX_ROBOTS
from vahr.domain import load_fleet
from vahr.domain.people import ACTION_KINDS, ALLOWED, ROLES, may
from vahr.skill_model.intents import BUILT_IN_INTENTS, CUSTOM_INTENTS

if TYPE_CHECKING:
    from vahr.domain import Fleet


def slot(name: str, said: str, *ids: str) -> Slot:
    """A slot as Alexa fills it; several ids when the words fit several values."""
    if not ids:
        return Slot(name=name, value=said)
    resolution = Resolution(
        authority="amzn1.er-authority.echo-sdk.test",
        status=Status(code=StatusCode.ER_SUCCESS_MATCH),
        values=[ValueWrapper(value=Value(name=said, id=value)) for value in ids],
    )
    return Slot(
        name=name, value=said, resolutions=Resolutions(resolutions_per_authority=[resolution])
    )


def intent(name: str, *slots: Slot) -> Intent:
    return Intent(name=name, slots={s.name: s for s in slots})


@pytest.mark.parametrize(
    ("role", "kind", "allowed"),
    [(role, kind, kind in ALLOWED[role]) for role in ROLES for kind in ACTION_KINDS],
)
def test_role_by_kind(role: str, kind: str, allowed: bool) -> None:
    expected = {
        "viewer": {"question", "stop"},
        "operator": {"question", "stop", "command"},
        "supervisor": {"question", "stop", "command", "fleet"},
    }
    assert may(role, kind) is allowed  # type: ignore[arg-type]
    assert allowed is (kind in expected[role])


def test_every_intent_of_the_interaction_model_has_a_kind() -> None:
    for name in [spec.name for spec in CUSTOM_INTENTS] + list(BUILT_IN_INTENTS):
        assert name in INTENT_RULES, f"{name} needs an entry in skill.access.INTENT_RULES"


@pytest.mark.parametrize(
    ("asked", "kind"),
    [
        (intent("StatusIntent"), "question"),
        (intent("TaskQueueIntent"), "question"),
        (intent("EmergencyStopIntent"), "stop"),
        (intent("EmergencyStopIntent", slot("robot", "all robots", "all")), "stop"),
        (intent("NavigateIntent", slot("robot", "placebot one", "placebot1")), "command"),
        (intent("NavigateIntent", slot("robot", "all robots", "all")), "fleet"),
        (intent("DeliverIntent", slot("robot", "everyone", "all")), "fleet"),
        (intent("WeatherDeliveryIntent", slot("robot", "all robots", "all")), "fleet"),
        (intent("CorrectionIntent", slot("robot", "all robots", "all")), "fleet"),
        (intent("CancelTaskIntent", slot("zone", "zone b", "B")), "command"),
        (intent("IdleRobotsIntent", slot("zone", "zone c", "C")), "fleet"),
        (intent("ZoneRobotsIntent", slot("origin", "zone a", "A")), "fleet"),
        # Intents of zone closures and service changes, whenever they arrive
        (intent("CloseZoneIntent", slot("zone", "zone b", "B")), "fleet"),
        (intent("OutOfServiceIntent", slot("robot", "placebot one", "placebot1")), "fleet"),
        # An intent nobody classified is the most guarded kind
        (intent("SomeNewIntent"), "fleet"),
    ],
)
def test_kind_of_each_request(asked: Intent, kind: str, fleet: Fleet) -> None:
    assert classify(asked, Vocabulary(fleet)) == kind


def test_an_unclear_robot_never_widens_to_the_fleet(fleet: Fleet) -> None:
    # "robot" fits both robots: not a fleet-wide command; the handler asks which one
    unclear = intent("NavigateIntent", slot("robot", "robot", "placebot1", "placebot2"))
    assert classify(unclear, Vocabulary(fleet)) == "command"
    unknown = intent("NavigateIntent", slot("robot", "rover nine"))
    assert classify(unknown, Vocabulary(fleet)) == "command"


def test_a_dispatch_is_fleet_wide_past_the_threshold_or_when_it_takes_every_robot(
    fleet: Fleet,
) -> None:
    six = load_fleet(SIX_ROBOTS)
    words = Vocabulary(six)
    # "send a robot", "send three robots": a few of six
    assert classify(intent("FleetNavigateIntent"), words, threshold=3) == "command"
    three = intent("FleetNavigateIntent", slot("count", "three"))
    assert robots_asked_for(three, six) == 3
    assert classify(three, words, threshold=3) == "command"
    # "send four robots": more than the threshold; "send the waders": three of them
    assert classify(intent("FleetNavigateIntent", slot("count", "4")), words, 3) == "fleet"
    waders = intent("FleetNavigateIntent", slot("group", "the waders", "waders"))
    assert classify(waders, words, threshold=3) == "command"
    assert classify(waders, words, threshold=2) == "fleet"
    # In the paper's fleet of two, "send two robots" is every robot
    two = intent("FleetNavigateIntent", slot("count", "two"))
    assert classify(two, Vocabulary(fleet), threshold=3) == "fleet"
