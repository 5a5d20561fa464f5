"""Build the skill's generated files from fleet.yaml and the intent definitions.

They are the skill package (manifest and en-US interaction model) and the fleet's JSON
twin inside the Lambda code (`lambda/skill/fleet.json`), which spares the skill's cold
start PyYAML. `build_files` returns every file as text, so writing and checking for drift
compare exactly the same bytes.
"""

from __future__ import annotations

import dataclasses
import hashlib
import json
import re
from pathlib import Path
from typing import TYPE_CHECKING, Any

from vahr.domain import FLEET_GROUP, FLEET_GROUP_NAMES, Group
from vahr.domain.fleet import spoken_in
from vahr.domain.invocation import INVOCATION_NAME
from vahr.domain.locale import load_language
from vahr.domain.text import number_variants, spell_numbers
from vahr.errors import VahrError
from vahr.skill_model.intents import (
    BUILT_IN_INTENTS,
    COUNT_TYPE,
    CUSTOM_INTENTS,
    GROUP_TYPE,
    LOCALE,
    PERCENT_TYPE,
    ROBOT_TYPE,
    ZONE_TYPE,
    IntentSpec,
)
from vahr.skill_model.locale_templates import locale_intents, template_locales
from vahr.skill_model.manifest import build_manifest

if TYPE_CHECKING:
    from vahr.domain import Fleet

# The ROBOT value that means every robot; the skill publishes once on the fleet topic for it.
FLEET_ROBOT_ID = FLEET_GROUP
FLEET_GROUP_ID = FLEET_GROUP
DEFAULT_FLEET_NAMES = FLEET_GROUP_NAMES

PACKAGE_DIR = Path("skill-package")
MODEL_PATH = PACKAGE_DIR / "interactionModels" / "custom" / f"{LOCALE}.json"
MANIFEST_PATH = PACKAGE_DIR / "skill.json"
FLEET_TWIN_PATH = Path("lambda") / "skill" / "fleet.json"

# Alexa's rules for sample utterances: lower-case words (apostrophes allowed, numbers spelled
# out) and slot references, separated by single spaces.
_WORD_OR_SLOT = r"(?:[a-zäöüß']+|\{[A-Za-z]+\})"
_SAMPLE = re.compile(rf"^{_WORD_OR_SLOT}(?: {_WORD_OR_SLOT})*$")
_SLOT_REF = re.compile(r"\{([A-Za-z]+)\}")

# Limits the model is held to, inside what Alexa accepts: a slot value (or synonym) of at
# most 140 characters and 50,000 values and synonyms in all (the limits Amazon states for
# custom slot types), and a model definition of at most 1,000,000 characters (the SMAPI
# `modelDefinition` length constraint). Sample utterances are kept to 200,000 characters in
# all, and an utterance to 200, far under the definition limit.
MAX_SLOT_VALUE_CHARS = 140
MAX_SLOT_VALUES = 50_000
MAX_MODEL_CHARS = 1_000_000
MAX_SAMPLE_CHARS = 200_000
MAX_UTTERANCE_CHARS = 200
# "send twenty robots" is the most a COUNT names; more is said as a group or "every idle robot".
MAX_COUNT = 20


class ModelError(VahrError):
    """The intents or the fleet would make an interaction model Alexa rejects or confuses."""


def build_files(
    fleet: Fleet, source: bytes, endpoint: dict[str, Any] | None = None
) -> dict[Path, str]:
    """Every generated file, keyed by its path from the repository root.

    `source` is the fleet file's bytes: the twin records their hash, so the skill can tell
    when fleet.yaml changed after the twin was written and read the YAML instead.
    `endpoint` is a deployed skill endpoint to keep in skill.json.
    """
    files = {
        MANIFEST_PATH: render(build_manifest(endpoint)),
        MODEL_PATH: render(build_interaction_model(fleet)),
        FLEET_TWIN_PATH: render(fleet_twin(fleet, source)),
    }
    for locale in template_locales():
        files[model_path(locale)] = render(build_locale_model(fleet, locale))
    return files


def fleet_twin(fleet: Fleet, source: bytes) -> dict[str, Any]:
    """The fleet as JSON plus the hash of the YAML it came from."""
    import msgspec

    return {
        "generated_from": "fleet.yaml by python -m vahr.skill_model; do not edit",
        "source_sha256": hashlib.sha256(source).hexdigest(),
        "fleet": msgspec.to_builtins(fleet),
    }


def render(document: dict[str, Any]) -> str:
    return json.dumps(document, indent=2, ensure_ascii=False) + "\n"


def build_interaction_model(
    fleet: Fleet, intents: tuple[IntentSpec, ...] = CUSTOM_INTENTS
) -> dict[str, Any]:
    """The interaction model for one locale: language model plus a skill-driven dialog.

    A slot type the fleet gives no value (GROUP, when the fleet has no group besides the
    whole fleet) is left out, with every slot and sample that needs it: Alexa refuses a
    custom type without values.
    """
    types = [
        robot_type(fleet),
        zone_type(fleet),
        group_type(fleet),
        count_type(),
        percent_type(),
    ]
    present = [slot_type for slot_type in types if slot_type["values"]]
    intents = for_types(intents, {slot_type["name"] for slot_type in present})
    check_samples(intents)
    custom = [
        {
            "name": intent.name,
            "slots": [
                {"name": slot.name, "type": slot.type, "samples": slot.answers}
                for slot in intent.slots
            ],
            "samples": list(intent.samples),
        }
        for intent in intents
    ]
    built_in = [{"name": name, "samples": []} for name in BUILT_IN_INTENTS]
    model = {
        "interactionModel": {
            "languageModel": {
                "invocationName": INVOCATION_NAME,
                "modelConfiguration": {"fallbackIntentSensitivity": {"level": "LOW"}},
                "intents": custom + built_in,
                "types": present,
            },
            # The handlers elicit missing slots themselves (Dialog.ElicitSlot), which needs a
            # dialog model that lists the slots and leaves delegation to the skill.
            "dialog": {
                "delegationStrategy": "SKILL_RESPONSE",
                "intents": [
                    {
                        "name": intent.name,
                        "delegationStrategy": "SKILL_RESPONSE",
                        "confirmationRequired": False,
                        "prompts": {},
                        "slots": [
                            {
                                "name": slot.name,
                                "type": slot.type,
                                "elicitationRequired": False,
                                "confirmationRequired": False,
                                "prompts": {},
                            }
                            for slot in intent.slots
                        ],
                    }
                    for intent in intents
                    if intent.slots
                ],
            },
            "prompts": [],
        }
    }
    check_limits(model)
    return model


def check_limits(model: dict[str, Any]) -> None:
    """Refuse a model larger than Alexa accepts (see the limits above)."""
    language = model["interactionModel"]["languageModel"]
    names = [
        name
        for slot_type in language["types"]
        for value in slot_type["values"]
        for name in [value["name"]["value"], *value["name"]["synonyms"]]
    ]
    if len(names) > MAX_SLOT_VALUES:
        raise ModelError(f"{len(names)} slot values and synonyms; Alexa takes {MAX_SLOT_VALUES}")
    for name in names:
        if len(name) > MAX_SLOT_VALUE_CHARS:
            raise ModelError(f"the slot value {name!r} is over {MAX_SLOT_VALUE_CHARS} characters")
    samples = [sample for intent in language["intents"] for sample in intent["samples"]]
    for sample in samples:
        if len(sample) > MAX_UTTERANCE_CHARS:
            raise ModelError(f"the sample {sample!r} is over {MAX_UTTERANCE_CHARS} characters")
    if sum(len(sample) for sample in samples) > MAX_SAMPLE_CHARS:
        raise ModelError(f"the sample utterances exceed {MAX_SAMPLE_CHARS} characters in all")
    if len(render(model)) > MAX_MODEL_CHARS:
        raise ModelError(f"the interaction model exceeds {MAX_MODEL_CHARS} characters")


def robot_type(fleet: Fleet) -> dict[str, Any]:
    """ROBOT: one value per thing (id = thing name) plus the whole fleet (id `all`)."""
    values = [_value(robot.thing, robot.spoken) for robot in fleet.robots]
    group = next((group for group in fleet.groups if group.id == FLEET_GROUP_ID), None)
    values.append(_value(FLEET_ROBOT_ID, group.spoken if group else list(DEFAULT_FLEET_NAMES)))
    _check_unique_names(ROBOT_TYPE, values)
    return {"name": ROBOT_TYPE, "values": values}


def zone_type(fleet: Fleet) -> dict[str, Any]:
    """ZONE: one value per zone (id = zone id, names = its spoken names)."""
    values = [_value(zone.id, zone.spoken) for zone in fleet.zones]
    _check_unique_names(ZONE_TYPE, values)
    return {"name": ZONE_TYPE, "values": values}


def group_type(fleet: Fleet) -> dict[str, Any]:
    """GROUP: one value per group of fleet.yaml other than the whole fleet (which is ROBOT's
    `all`), id = group id, names = its spoken names."""
    values = [_value(group.id, group.spoken) for group in fleet.groups if group.id != FLEET_GROUP]
    _check_unique_names(GROUP_TYPE, values)
    return {"name": GROUP_TYPE, "values": values}


def count_type() -> dict[str, Any]:
    """COUNT: how many robots a task asks for, two to MAX_COUNT whatever the fleet's size
    (so that "send nine robots" to a fleet of six is heard, and answered with how many it
    has), spelled out ("two", id "2"); "a robot" and "one robot" are words of the samples."""
    values = [_value(str(n), [spell_numbers(str(n))]) for n in range(2, MAX_COUNT + 1)]
    return {"name": COUNT_TYPE, "values": values}


def percent_type() -> dict[str, Any]:
    """PERCENT: a battery's charge, five to a hundred in steps of five, spelled out
    ("thirty", id "30"), as people say a threshold."""
    values = [_value(str(n), [spell_numbers(str(n))]) for n in range(5, 101, 5)]
    return {"name": PERCENT_TYPE, "values": values}


def for_types(intents: tuple[IntentSpec, ...], types: set[str]) -> tuple[IntentSpec, ...]:
    """The intents without the slots whose type is not in `types`, and without the samples
    that name such a slot; an intent left with no sample is left out."""
    kept = []
    for intent in intents:
        missing = {slot.name for slot in intent.slots if slot.type not in types}
        if not missing:
            kept.append(intent)
            continue

        def names_none(template: str, missing: set[str] = missing) -> bool:
            return not any("{" + name + "}" in template for name in missing)

        trimmed = dataclasses.replace(
            intent,
            slots=tuple(slot for slot in intent.slots if slot.name not in missing),
            templates=tuple(filter(names_none, intent.templates)),
            essentials=tuple(filter(names_none, intent.essentials)),
        )
        if trimmed.templates or trimmed.essentials:
            kept.append(trimmed)
    return tuple(kept)


def _value(value_id: str, spoken: list[str]) -> dict[str, Any]:
    name, *synonyms = [" ".join(words.lower().split()) for words in spoken]
    return {"id": value_id, "name": {"value": name, "synonyms": synonyms}}


def _check_unique_names(type_name: str, values: list[dict[str, Any]]) -> None:
    # Alexa resolves a name to every value that lists it; one name must mean one thing.
    owner: dict[str, str] = {}
    for value in values:
        for name in [value["name"]["value"], *value["name"]["synonyms"]]:
            if owner.setdefault(name, value["id"]) != value["id"]:
                raise ModelError(
                    f"{type_name}: the name {name!r} is used by both "
                    f"{owner[name]!r} and {value['id']!r} in fleet.yaml"
                )


def utterance_shape(intent: IntentSpec, sample: str) -> str:
    """The sample with each slot replaced by its type: what the NLU actually matches."""
    types = {slot.name: slot.type for slot in intent.slots}
    return _SLOT_REF.sub(lambda found: "{" + types.get(found[1], found[1]) + "}", sample)


def check_samples(intents: tuple[IntentSpec, ...]) -> None:
    """Refuse malformed samples, unknown slots, and any shape shared by two intents."""
    seen: dict[str, str] = {}
    for intent in intents:
        slot_names = {slot.name for slot in intent.slots}
        for sample in intent.samples:
            if not _SAMPLE.match(sample):
                raise ModelError(
                    f"{intent.name}: sample {sample!r} must be lower-case words and "
                    "{slot} references separated by single spaces"
                )
            for slot in _SLOT_REF.findall(sample):
                if slot not in slot_names:
                    raise ModelError(f"{intent.name}: sample {sample!r} uses unknown slot {slot}")
            shape = utterance_shape(intent, sample)
            other = seen.setdefault(shape, intent.name)
            if other != intent.name:
                raise ModelError(
                    f"the utterance {shape!r} appears in both {other} and {intent.name}"
                )
        if len(set(intent.samples)) != len(intent.samples):
            raise ModelError(f"{intent.name}: a sample utterance is listed twice")
    # An answer to an elicitation must not read like the start of another intent, or the
    # person answering "which robot?" would launch that intent instead.
    for intent in intents:
        for slot in intent.slots:
            for answer in slot.answers:
                other = seen.get(utterance_shape(intent, answer), intent.name)
                if other != intent.name:
                    raise ModelError(
                        f"{intent.name}: the answer {answer!r} for slot {slot.name} "
                        f"is also a sample of {other}"
                    )


def deployed_endpoint(root: Path) -> dict[str, Any] | None:
    """The `apis.custom.endpoint` of the skill.json under `root`, if a deployment wrote one."""
    try:
        manifest = json.loads((root / MANIFEST_PATH).read_text(encoding="utf-8"))
        endpoint = manifest["manifest"]["apis"]["custom"].get("endpoint")
    except (OSError, ValueError, KeyError, TypeError, AttributeError):
        return None
    return endpoint if isinstance(endpoint, dict) else None


def _stale(root: Path, fleet: Fleet, source: bytes) -> dict[Path, str]:
    """The generated files under `root` that differ from the generator's, with its text."""
    stale = {}
    for relative, text in build_files(fleet, source, deployed_endpoint(root)).items():
        target = root / relative
        if not target.exists() or target.read_text(encoding="utf-8") != text:
            stale[target] = text
    return stale


def write(root: Path, fleet: Fleet, source: bytes) -> list[Path]:
    """Write the generated files under `root` and return those that changed."""
    stale = _stale(root, fleet, source)
    for target, text in stale.items():
        target.parent.mkdir(parents=True, exist_ok=True)
        target.write_text(text, encoding="utf-8")
    return list(stale)


def drift(root: Path, fleet: Fleet, source: bytes) -> list[Path]:
    """The generated files under `root` that differ from what the generator would write."""
    return list(_stale(root, fleet, source))


# The slot type that counts robots (`intents.COUNT_TYPE`), said in the locale's numbers.
COUNT_TYPE_NAME = "COUNT"


def model_path(locale: str) -> Path:
    """Where the interaction model of `locale` is written, from the repository root."""
    return PACKAGE_DIR / "interactionModels" / "custom" / f"{locale}.json"


def in_locale(fleet: Fleet, locale: str) -> Fleet:
    """`fleet` with every robot's, zone's and group's `spoken` names those of `locale`
    (its `spoken_by_locale` names, else the en-US ones)."""
    import msgspec

    groups = [msgspec.structs.replace(g, spoken=spoken_in(g, locale)) for g in fleet.groups]
    if not any(group.id == FLEET_GROUP_ID for group in groups):
        # The whole fleet by the language's own words, not English ones.
        names = load_language(locale).fleet_names
        groups.append(Group(id=FLEET_GROUP_ID, spoken=names, robots=list(fleet.robot_things)))
    return msgspec.structs.replace(
        fleet,
        robots=[msgspec.structs.replace(r, spoken=spoken_in(r, locale)) for r in fleet.robots],
        zones=[msgspec.structs.replace(z, spoken=spoken_in(z, locale)) for z in fleet.zones],
        groups=groups,
    )


def build_locale_model(fleet: Fleet, locale: str) -> dict[str, Any]:
    """The interaction model of a locale with templates (`locale_templates`): its intents,
    its invocation name, the fleet's names in it, and counts in its number words."""
    model = build_interaction_model(in_locale(fleet, locale), locale_intents(locale))
    language = model["interactionModel"]["languageModel"]
    language["invocationName"] = load_language(locale).invocation_name
    for slot_type in language["types"]:
        if slot_type["name"] not in (COUNT_TYPE_NAME, PERCENT_TYPE):
            continue
        for value in slot_type["values"]:
            number = int(value["id"])
            value["name"] = {
                "value": spell_numbers(str(number), locale=locale),
                "synonyms": number_variants(number, locale),
            }
    check_limits(model)
    return model
