"""A place or group the fleet does not have is answered with those it has, in both
languages, as docs/dispatch.md promises: the NLU reads an unknown place where a request
puts one as the zone slot's unresolved value (as Alexa does), and the skill says it knows
no such place and lists the zones (or groups). Nothing is sent."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import pytest
from skill_testkit import published

from tests.support.fleets import HOSPITAL
from vahr.assistant.nlu import InteractionModel
from vahr.assistant.simulator import AlexaSimulator
from vahr.assistant.understanding import load_understanding
from vahr.domain import load_fleet
from vahr.skill_model.generator import build_interaction_model, build_locale_model

if TYPE_CHECKING:
    from collections.abc import Callable

FLEET = load_fleet(HOSPITAL)


@pytest.fixture(scope="module")
def models() -> dict[str, InteractionModel]:
    return {
        "en-US": InteractionModel(build_interaction_model(FLEET)),
        "de-DE": InteractionModel(
            build_locale_model(FLEET, "de-DE"), understanding=load_understanding("de-DE")
        ),
    }


@pytest.mark.parametrize(
    ("locale", "utterance", "answer"),
    [
        (
            "en-US",
            "send a robot to the cafeteria",
            "I don't know a zone called the cafeteria. "
            "To which zone: the dock, the pharmacy, ward three, reception, or the lab?",
        ),
        (
            "en-US",
            "send hermes to the cafeteria",
            "I don't know a zone called the cafeteria. "
            "To which zone: the dock, the pharmacy, ward three, reception, or the lab?",
        ),
        (
            "en-US",
            "send the night shift to the lab",
            "I don't know a group called the night shift; the groups are the day shift.",
        ),
        (
            "de-DE",
            "schick einen roboter in die kantine",
            "Eine Zone namens die kantine kenne ich nicht. "
            "In welche Zone: Dock, Apotheke, Station Drei, Empfang oder Labor?",
        ),
        (
            "de-DE",
            "schick hermes in die kantine",
            "Eine Zone namens die kantine kenne ich nicht. "
            "In welche Zone: Dock, Apotheke, Station Drei, Empfang oder Labor?",
        ),
    ],
)
def test_an_unknown_place_is_answered_with_the_places_there_are(
    make_skill: Callable[..., Any],
    models: dict[str, InteractionModel],
    locale: str,
    utterance: str,
    answer: str,
) -> None:
    skill = make_skill(fleet_file=str(HOSPITAL))
    alexa = AlexaSimulator(models[locale], skill, locale=locale)
    turn = alexa.say(utterance)
    assert turn.speech == answer
    assert published() == []
