"""`vahr up`'s banner suggests a first command that the stack it started takes: in the
language it runs in, with `--locale` when that is not English, in the fleet's own names."""

from __future__ import annotations

import shlex

import pytest

from tests.support.fleets import HOSPITAL
from vahr.assistant.nlu import InteractionModel
from vahr.assistant.understanding import load_understanding
from vahr.commands.up import example_command
from vahr.domain import load_fleet
from vahr.skill_model.generator import build_interaction_model, build_locale_model


@pytest.mark.parametrize(
    ("fleet_file", "locale", "expected", "robot", "zone"),
    [
        (None, "en-US", 'vahr say "send placebot one to zone a"', "placebot1", "A"),
        (
            None,
            "de-DE",
            'vahr say --locale de-DE "schicke placebot eins in zone a"',
            "placebot1",
            "A",
        ),
        (HOSPITAL, "en-US", 'vahr say "send hermes to the pharmacy"', "hermes", "PHARMACY"),
        (
            HOSPITAL,
            "de-DE",
            'vahr say --locale de-DE "schicke hermes in apotheke"',
            "hermes",
            "PHARMACY",
        ),
    ],
)
def test_the_suggested_command_is_understood_in_the_stacks_language(
    fleet_file: object, locale: str, expected: str, robot: str, zone: str
) -> None:
    fleet = load_fleet(fleet_file)  # type: ignore[arg-type]
    suggested = example_command(fleet, locale)
    assert suggested == expected
    utterance = shlex.split(suggested)[-1]
    document = (
        build_interaction_model(fleet) if locale == "en-US" else build_locale_model(fleet, locale)
    )
    model = InteractionModel(document, understanding=load_understanding(locale))
    understood = model.understand(utterance)
    assert understood.intent == "NavigateIntent"
    assert {name: value.id for name, value in understood.slots.items()} == {
        "robot": robot,
        "zone": zone,
    }
