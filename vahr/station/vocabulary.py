"""What push-to-talk listens for: sentences made from the skill's interaction model.

Every sample utterance of every intent (but the weather rule's, below) is written out with
its slots filled, each slot going through all of its type's values and synonyms across the
copies of the sample (so every value appears in every sample's context once, without
multiplying out samples with several slots; past `MAX_COPIES` names, as in a fleet of a
thousand robots, the samples share the names out between them instead, each name still in
many contexts), plus the built-in intents' phrases (those the simulator knows them by,
`vahr.assistant.built_in_phrases`), the invocation forms ("ask robot fleet to ...") and
the yes and no that answer a yes-or-no question.
The interaction model is generated from `fleet.yaml`, so the robots' and zones' names follow
the fleet. Numbers are spelled out, as people say them.

The station's recognizer is built from them in a child process (`command_recognizer`):
with a fleet of 1,000 robots the sentences and their language model take about a minute of
pure Python, which inside the station would hold the interpreter lock its MQTT intake
needs. The model is cached on disk by a hash of what it is built from, so the next start
only loads it, in the station itself (0.4 s of CPU for 1,000 robots; a child's interpreter
and imports alone took most of a second).
"""

from __future__ import annotations

import json
import logging
import re
import time
from pathlib import Path
from typing import TYPE_CHECKING, Any, NamedTuple

import msgspec

from vahr.assistant import DEFAULT_MODEL, RULE_SLOTS, built_in_phrases, confirmation_phrases
from vahr.domain.fleet import zone_phrase
from vahr.domain.text import normalize, spell_numbers
from vahr.errors import VahrError
from vahr.model_cache import code_digest, content_key, write_atomically

if TYPE_CHECKING:
    from vahr.domain import Fleet
    from vahr.speech.lm_stt import LanguageModel, LanguageModelRecognizer

log = logging.getLogger(__name__)

_SLOT = re.compile(r"\{([A-Za-z0-9_.]+)\}")
# The weather delivery's rule said aloud ("deliver to zone a if it's sunny and zone c if it's
# raining") is left out: its zone-and-weather sentences, filled with every name, crowded the
# model until "send placebot two to zone c" was heard "send placebots to that zone c" (the
# whole fleet) in the browser test. The weather delivery itself is still heard.
_RULE_SLOTS = frozenset(RULE_SLOTS.values())
# The most copies of one sample. The paper's fleet has 69 zone names and 44 robot names, so
# its sentences are unchanged; a swarm of 1,000 robots (about 3,000 names) would otherwise
# write each sample 3,000 times, 1.2 million sentences whose model took 40 s of CPU to build
# inside the station, while its MQTT intake waited on the interpreter lock.
MAX_COPIES = 100
# Ways of leaving a session, which the simulator answers like Alexa does.
EXITS = ("exit", "goodbye", "stop", "cancel")


def _phrase(text: str) -> str:
    return spell_numbers(normalize(text))


def sentences(document: dict[str, Any]) -> list[str]:
    """The sentences of an interaction model (its JSON), normalized, without repeats."""
    try:
        language = document["interactionModel"]["languageModel"]
        invocation = _phrase(language["invocationName"])
        values = {
            slot_type["name"]: [
                _phrase(phrase)
                for value in slot_type.get("values", [])
                for phrase in [value["name"]["value"], *value["name"].get("synonyms", [])]
            ]
            for slot_type in language.get("types", [])
        }
        found: list[str] = []
        shared = 0  # how far the samples together have gone through the longest name lists
        built_in = built_in_phrases()
        for intent in language["intents"]:
            types = {slot["name"]: slot["type"] for slot in intent.get("slots", [])}
            samples = intent.get("samples") or built_in.get(intent["name"], [])
            for sample in samples:
                if _RULE_SLOTS & set(_SLOT.findall(sample)):
                    continue
                filled = _filled(sample, types, values, shared)
                shared += MAX_COPIES
                found += filled
                found.append(f"ask {invocation} to {filled[0]}")
    except (KeyError, TypeError) as err:
        raise VahrError(f"the interaction model lacks {err}") from err
    # The yes and no that answer the skill's yes-or-no questions ("Placebot two instead?"),
    # which no sample holds.
    found += [_phrase(phrase) for phrase in confirmation_phrases()]
    found += [f"open {invocation}", f"alexa open {invocation}", *EXITS]
    return list(dict.fromkeys(s for s in found if s))


def _filled(
    sample: str, types: dict[str, str], values: dict[str, list[str]], shared: int = 0
) -> list[str]:
    """Copies of `sample` with its slots filled, every value of every slot used once; a slot
    with more than `MAX_COPIES` values goes on from `shared`, where the last sample left."""
    slots = _SLOT.findall(sample)
    choices = [values.get(types.get(slot, ""), []) or [slot.lower()] for slot in slots]
    copies = min(max((len(options) for options in choices), default=1), MAX_COPIES)
    filled = []
    for copy in range(copies):
        text = sample
        for position, options in enumerate(choices):
            start = shared if len(options) > MAX_COPIES else 0
            # Slots of one sample go through their values out of step with each other.
            chosen = options[(start + copy + 7 * position) % len(options)]
            text = _SLOT.sub(chosen.replace("\\", "\\\\"), text, count=1)
        filled.append(_phrase(text))
    return filled


def load_model(model_file: Path | None = None) -> dict[str, Any]:
    file = model_file or DEFAULT_MODEL
    try:
        loaded: dict[str, Any] = json.loads(Path(file).read_text(encoding="utf-8"))
    except OSError as err:
        raise VahrError(f"cannot read the interaction model {file}: {err.strerror}") from err
    except ValueError as err:
        raise VahrError(f"the interaction model {file} is not valid JSON: {err}") from err
    return loaded


class CommandModel(NamedTuple):
    """The push-to-talk sentences and their language model, as the child sends them back."""

    sentences: list[str]
    model: LanguageModel
    cached: bool  # read from the cache rather than built
    seconds: float  # the child's time for the sentences and the model


def command_model(
    model_file: Path | None, fleet: Fleet | None, cache_dir: Path | None
) -> CommandModel:
    """The sentences of the interaction model (as `command_recognizer` picks it) and their
    language model, from the cache in `cache_dir` or built (what the child process runs)."""
    from vahr.speech.lm_stt import cached_language_model

    started = time.perf_counter()
    document = _document(model_file, fleet)
    found, listed = cached_sentences(document, cache_dir)
    model, cached = cached_language_model(found, cache_dir=cache_dir)
    return CommandModel(found, model, listed and cached, time.perf_counter() - started)


def cached_command_model(
    model_file: Path | None, fleet: Fleet | None, cache_dir: Path
) -> CommandModel | None:
    """`command_model` when the cache in `cache_dir` holds both the sentences and their
    language model; None, building nothing, when it lacks either."""
    from vahr.speech.lm_stt import read_cached_language_model

    started = time.perf_counter()
    file, key = _sentences_file(_document(model_file, fleet), cache_dir)
    found = _read_sentences(file, key)
    model = read_cached_language_model(found, cache_dir=cache_dir) if found else None
    if found is None or model is None:
        return None
    return CommandModel(found, model, True, time.perf_counter() - started)


def _document(model_file: Path | None, fleet: Fleet | None) -> dict[str, Any]:
    """The interaction model `command_recognizer` listens for (see there)."""
    if model_file is None and fleet is not None:
        from vahr.skill_model.generator import build_interaction_model

        return build_interaction_model(fleet)
    return load_model(model_file)


class _CachedSentences(msgspec.Struct, frozen=True):
    """An interaction model's sentences as the cache keeps them, with their key."""

    key: str
    sentences: list[str]


def cached_sentences(document: dict[str, Any], cache_dir: Path | None) -> tuple[list[str], bool]:
    """`sentences(document)`, from the cache in `cache_dir` when it holds them (True) or
    written out now and kept (False). Writing out a fleet's 185,000 sentences took most of
    the station's start (3 s of CPU); the language model is then read from its own cache by
    their hash. The key is everything they are made from: the document, the phrases added
    to it, and the code that writes them out (this module's and the text's)."""
    file, digest = _sentences_file(document, cache_dir)
    kept = _read_sentences(file, digest)
    if kept is not None:
        return kept, True
    found = sentences(document)
    if file is not None:
        write_atomically(file, msgspec.json.encode(_CachedSentences(digest, found)))
    return found, False


def _sentences_file(document: dict[str, Any], cache_dir: Path | None) -> tuple[Path | None, str]:
    """Where the cache keeps `document`'s sentences, and their key (`cached_sentences`)."""
    made_from = [
        code_digest(__name__, "vahr.domain.text"), built_in_phrases(), confirmation_phrases(),
        document,
    ]  # fmt: skip
    digest = content_key(made_from)
    return (cache_dir / f"sentences-{digest[:24]}.json" if cache_dir else None), digest


def _read_sentences(file: Path | None, digest: str) -> list[str] | None:
    if file is None:
        return None
    try:
        kept = msgspec.json.decode(file.read_bytes(), type=_CachedSentences)
    except (OSError, msgspec.DecodeError):
        return None  # not there yet, or damaged: written out again
    return kept.sentences if kept.key == digest else None


def command_recognizer(
    model_file: Path | None = None,
    fleet: Fleet | None = None,
    *,
    cache_dir: Path | None = None,
    use_cache: bool = True,
) -> LanguageModelRecognizer:
    """The push-to-talk recognizer for the interaction model at `model_file`; without one,
    the model generated from `fleet` (in memory), else the one that ships with the package.
    Its sentences and language model are read from the cache here, or made in a child
    process when the cache lacks them; the decoder is loaded here. The model is cached in
    `cache_dir` (default: the trained models' cache, `$XDG_CACHE_HOME/vahr`) unless
    `use_cache` is False."""
    from vahr.model_cache import default_cache_dir
    from vahr.speech.lm_stt import LanguageModelRecognizer, in_child_process

    cache = (cache_dir or default_cache_dir()) if use_cache else None
    started = time.perf_counter()
    made = cached_command_model(model_file, fleet, cache) if cache else None
    where = "read from the cache"
    if made is None:
        made = in_child_process(command_model, model_file, fleet, cache)
        where = ("read from the cache" if made.cached else "built") + " in a child process"
    received = time.perf_counter()
    recognizer = LanguageModelRecognizer(made.sentences, nbest=True, model=made.model)
    log.info(
        "push-to-talk: %d sentences, language model %s in %.1f s (%.1f s in all), loaded in %.2f s",
        len(made.sentences),
        where,
        made.seconds,
        received - started,
        time.perf_counter() - received,
    )
    return recognizer


# Robots named in Whisper's prompt: a prompt holds at most 224 tokens, and a few names
# show the model how the fleet's names are spelled.
PROMPT_ROBOTS = 6


def whisper_prompt(fleet: Fleet, invocation: str = "robot fleet") -> str:
    """What Whisper is told came before the clip: commands naming the fleet's robots and
    zones as the skill writes them, so it spells "placebot one" and "zone B", not "plus
    bar 1" and "zone be". For the default fleet: "Robot fleet: send placebot one to zone A.
    Placebot two, go to the loading zone. Deliver to zone A, zone B, zone C or zone D."."""
    robots = [fleet.spoken_name(thing) for thing in fleet.robot_things[:PROMPT_ROBOTS]]
    zones = {zone.id: zone_phrase(zone) for zone in fleet.zones}
    loading = zones.pop("LOADING")
    delivery = list(zones.values()) or [loading]
    sentences = [f"send {robots[0]} to {delivery[0]}."]
    sentences += [f"{robot[:1].upper()}{robot[1:]}, go to {loading}." for robot in robots[1:]]
    listed = ", ".join(delivery[:-1]) + f" or {delivery[-1]}" if len(delivery) > 1 else delivery[0]
    sentences.append(f"Deliver to {listed}.")
    return f"{invocation[:1].upper()}{invocation[1:]}: " + " ".join(sentences)
