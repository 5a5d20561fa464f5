"""The German interaction model: generated from the de-DE templates and the fleet's German
names, valid for ASK, with every intent of the skill, and German in the store listing."""

from __future__ import annotations

import json
import re
from pathlib import Path
from typing import Any

import pytest
from ask_sdk_core.serialize import DefaultSerializer

from vahr.domain import load_fleet
from vahr.errors import VahrError
from vahr.skill_model.generator import build_locale_model, model_path, render
from vahr.skill_model.intents import CUSTOM_INTENTS
from vahr.skill_model.locale_templates import locale_intents
from vahr.skill_model.manifest import build_manifest

ROOT = Path(__file__).resolve().parents[3]
MODEL_TYPE = (
    "ask_smapi_model.v1.skill.interaction_model.interaction_model_data.InteractionModelData"
)
MANIFEST_TYPE = "ask_smapi_model.v1.skill.manifest.skill_manifest_envelope.SkillManifestEnvelope"


@pytest.fixture(scope="module")
def model() -> dict[str, Any]:
    loaded: dict[str, Any] = json.loads((ROOT / model_path("de-DE")).read_text())
    return loaded


def test_the_committed_german_model_is_what_the_generator_writes(model: dict[str, Any]) -> None:
    assert render(build_locale_model(load_fleet(ROOT / "fleet.yaml"), "de-DE")) == render(model)


def test_the_german_model_deserializes_with_ask_smapi_model_classes(model: dict[str, Any]) -> None:
    serializer = DefaultSerializer()
    parsed = serializer.deserialize(json.dumps(model), MODEL_TYPE)
    # A round trip drops any field the ASK schema does not know.
    assert serializer.serialize(parsed) == model


def test_every_intent_of_the_skill_has_german_samples(model: dict[str, Any]) -> None:
    language = model["interactionModel"]["languageModel"]
    german = {intent["name"]: intent for intent in language["intents"]}
    assert {intent.name for intent in CUSTOM_INTENTS} <= german.keys()
    english = json.loads((ROOT / model_path("en-US")).read_text())["interactionModel"]
    for intent in english["languageModel"]["intents"]:
        if intent["name"].startswith("AMAZON."):
            continue
        # The same slots as in English, each answered in German when the skill asks for it.
        same = german[intent["name"]]
        assert len(same["samples"]) >= 20, intent["name"]
        assert [(s["name"], s["type"]) for s in same["slots"]] == [
            (s["name"], s["type"]) for s in intent["slots"]
        ]


def test_the_german_model_speaks_german(model: dict[str, Any]) -> None:
    language = model["interactionModel"]["languageModel"]
    assert language["invocationName"] == "roboterflotte"
    samples = {s for intent in language["intents"] for s in intent["samples"]}
    # Verb last after "lass", a compound, and the fleet's German names with "zwo".
    assert "lass {robot} nach {zone} fahren" in samples
    assert any("wetterlieferung" in sample for sample in samples)
    names = {
        name
        for slot_type in language["types"]
        for value in slot_type["values"]
        for name in [value["name"]["value"], *value["name"]["synonyms"]]
    }
    assert {"placebot zwo", "placebot eins", "ladezone", "alle roboter"} <= names
    for sample in samples:
        assert re.fullmatch(r"(?:[a-zäöüß']+|\{\w+\})(?: (?:[a-zäöüß']+|\{\w+\}))*", sample)


def test_the_manifest_lists_the_german_store_entry() -> None:
    manifest = build_manifest()
    serializer = DefaultSerializer()
    parsed = serializer.deserialize(json.dumps(manifest), MANIFEST_TYPE)
    assert serializer.serialize(parsed) == manifest
    german = manifest["manifest"]["publishingInformation"]["locales"]["de-DE"]
    assert (
        german["examplePhrases"][1] == "Alexa, sage roboterflotte, schicke placebot eins in zone a"
    )


def test_a_template_naming_no_intent_of_the_skill_is_one_line(tmp_path: Path) -> None:
    (tmp_path / "xx-XX").mkdir()
    (tmp_path / "xx-XX" / "templates.yaml").write_text(
        "answers: {}\nintents:\n  FlyIntent:\n    templates: [flieg]\n"
    )
    with pytest.raises(VahrError, match="'FlyIntent' is not an intent of the skill"):
        locale_intents("xx-XX", directory=tmp_path)
