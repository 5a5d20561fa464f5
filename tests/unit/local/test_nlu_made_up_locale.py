"""A third locale is data only: a made-up language understood from its data files alone.

Given `tests/data/locales/xx-XX/` (invented words: "zub robo un ka plak be" sends robot one
to zone B), its interaction model is generated from `templates.yaml` with the skill
model's template expander, and the simulator's NLU is built from that model and the
locale's `understanding.yaml`: no code knows a word of the language. The sentences asked
below are not among the generated samples (the test holds it).
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import msgspec
import pytest

from vahr.errors import VahrError
from vahr.local.alexa.nlu import FALLBACK, InteractionModel
from vahr.local.alexa.understanding import load_understanding
from vahr.skill_model.templates import expand

LOCALES = Path(__file__).resolve().parents[2] / "data" / "locales"
LOCALE = "xx-XX"


class MadeUpTemplates(msgspec.Struct, frozen=True, forbid_unknown_fields=True):
    invocation: str
    slot_types: dict[str, dict[str, list[str]]]
    intents: dict[str, dict[str, Any]]


def interaction_model(templates: MadeUpTemplates) -> dict[str, Any]:
    """The locale's interaction model document, as the skill model's generator shapes it."""
    intents = []
    for name, spec in templates.intents.items():
        slots = spec.get("slots", {})
        samples = [s for template in spec.get("templates", []) for s in expand(template)]
        intents.append(
            {
                "name": name,
                "slots": [{"name": slot, "type": kind} for slot, kind in slots.items()],
                "samples": samples,
            }
        )
    types = [
        {
            "name": kind,
            "values": [
                {"id": value, "name": {"value": names[0], "synonyms": names[1:]}}
                for value, names in values.items()
            ],
        }
        for kind, values in templates.slot_types.items()
    ]
    return {
        "interactionModel": {
            "languageModel": {
                "invocationName": templates.invocation,
                "intents": intents,
                "types": types,
            }
        }
    }


@pytest.fixture(scope="module")
def document() -> dict[str, Any]:
    source = (LOCALES / LOCALE / "templates.yaml").read_bytes()
    return interaction_model(msgspec.yaml.decode(source, type=MadeUpTemplates))


@pytest.fixture(scope="module")
def model(document: dict[str, Any], tmp_path_factory: pytest.TempPathFactory) -> InteractionModel:
    file: Path = tmp_path_factory.mktemp("models") / f"{LOCALE}.json"
    file.write_text(json.dumps(document))
    understanding = load_understanding(LOCALE, directory=LOCALES)
    return InteractionModel.load(file, use_cache=False, understanding=understanding)


def samples_of(document: dict[str, Any]) -> set[str]:
    return {
        sample
        for intent in document["interactionModel"]["languageModel"]["intents"]
        for sample in intent["samples"]
    }


@pytest.mark.parametrize(
    ("utterance", "intent", "slots"),
    [
        ("zub robo un ka plak be", "NavigateIntent", {"robot": "robo1", "zone": "B"}),
        ("plis robo du vad kaa plak ce", "NavigateIntent", {"robot": "robo2", "zone": "C"}),
        # Listed robots that are the whole fleet, and a zone the robot comes from.
        ("mov robo un e robo du ka plak a", "NavigateIntent", {"robot": "all", "zone": "A"}),
        ("zub robo du de plak a ka plak ce", "NavigateIntent", {"robot": "robo2", "zone": "C"}),
        # The roles follow the sentence: "apre" (after) puts the robot named second first.
        ("robo un liv plak be pos robo du fez plak ce", "SequentialDeliveryIntent",
         {"firstRobot": "robo1", "firstZone": "B", "secondRobot": "robo2", "secondZone": "C"}),
        ("robo du fez plak ce apre robo un liv plak a", "SequentialDeliveryIntent",
         {"firstRobot": "robo1", "firstZone": "A", "secondRobot": "robo2", "secondZone": "C"}),
    ],
)  # fmt: skip
def test_a_made_up_locale_is_understood_from_its_data(
    model: InteractionModel,
    document: dict[str, Any],
    utterance: str,
    intent: str,
    slots: dict[str, str],
) -> None:
    # Given sentences the generated samples do not hold word for word
    assert utterance not in samples_of(document)
    # When the locale's NLU hears one
    understood = model.understand(utterance)
    # Then the intent and every slot's role are the ones meant
    assert understood.intent == intent
    assert {name: value.id for name, value in understood.slots.items()} == slots


@pytest.mark.parametrize("utterance", ["sona la radio", "dona me kafe e pan", "kom vas tu"])
def test_its_out_of_domain_sentences_fall_back(model: InteractionModel, utterance: str) -> None:
    # Not the out-of-domain phrases it trains on, but their kind
    assert model.understand(utterance).intent == FALLBACK


def test_its_built_in_phrases_train_the_built_in_intents(model: InteractionModel) -> None:
    assert model.understand("ajuta plis").intent == "AMAZON.HelpIntent"


def test_a_locale_without_understanding_data_is_one_line() -> None:
    expected = r"no understanding data for the locale 'yy-YY' \(have: xx-XX\)"
    with pytest.raises(VahrError, match=expected):
        load_understanding("yy-YY", directory=LOCALES)


def test_a_role_example_naming_no_slot_is_one_line(document: dict[str, Any]) -> None:
    # Given the locale's data with a misspelt slot in a role example
    understanding = load_understanding(LOCALE, directory=LOCALES)
    typo = msgspec.structs.replace(understanding.roles[0], examples=["zub {robot} ka {zon}"])
    broken = msgspec.structs.replace(understanding, roles=[typo])
    # When the NLU is built from it, Then one line names the intent and the reference
    with pytest.raises(VahrError, match=r"role examples of NavigateIntent: \{zon\} in 'zub"):
        InteractionModel(document, use_cache=False, understanding=broken)
