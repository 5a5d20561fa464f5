"""Sample templates: the syntax expands as written, the generated samples are varied and
reproducible, and the generator holds the model to Alexa's limits."""

from __future__ import annotations

import copy
import json
import random
import re
from pathlib import Path
from typing import TYPE_CHECKING, Any

import pytest

from vahr.skill_model import ModelError, build_interaction_model
from vahr.skill_model.generator import (
    MAX_SAMPLE_CHARS,
    MAX_SLOT_VALUE_CHARS,
    MODEL_PATH,
    check_limits,
)
from vahr.skill_model.intents import CUSTOM_INTENTS, IntentSpec, SlotSpec
from vahr.skill_model.phrases import RULES
from vahr.skill_model.templates import TemplateError, draw, expand

if TYPE_CHECKING:
    from vahr.domain import Fleet

ROOT = Path(__file__).resolve().parents[3]


def test_alternatives_optional_words_and_rules_expand() -> None:
    sentences = expand("[please] (send|move) {robot} <to> {zone}", {"to": "(to|over to)"})
    assert sentences == [
        "please send {robot} to {zone}",
        "please send {robot} over to {zone}",
        "please move {robot} to {zone}",
        "please move {robot} over to {zone}",
        "send {robot} to {zone}",
        "send {robot} over to {zone}",
        "move {robot} to {zone}",
        "move {robot} over to {zone}",
    ]


@pytest.mark.parametrize(
    ("template", "message"),
    [
        ("(send|move {robot}", "missing ')'"),
        ("send {robot})", "unexpected ')'"),
        ("send <nobody>", "unknown rule <nobody>"),
        ("(send]", "']' closes '('"),
    ],
)
def test_a_malformed_template_is_named_in_the_error(template: str, message: str) -> None:
    with pytest.raises(TemplateError, match=re.escape(message)):
        expand(template, {})


def test_a_rule_that_refers_to_itself_is_refused() -> None:
    with pytest.raises(TemplateError, match="refers to itself"):
        expand("<loop>", {"loop": "a [<loop>]"})


def test_a_large_template_is_drawn_from_reproducibly() -> None:
    template = "<ask> <send> {robot} <way> <to> {zone} <end>"
    first = draw(template, RULES, random.Random("seed"), 50)
    assert len(first) == len(set(first)) == 50
    assert first == draw(template, RULES, random.Random("seed"), 50)
    assert all(sentence in expand(template, RULES) for sentence in first[:5])


def test_every_robot_command_intent_has_varied_samples() -> None:
    for intent in CUSTOM_INTENTS:
        if not intent.commands_robots:
            continue
        samples = intent.samples
        assert len(samples) >= 60, intent.name
        assert len(set(samples)) == len(samples)
        # Varied: the robot named before and after the verb, polite and bare, with fillers.
        assert any(s.startswith("{") for s in samples), intent.name
        if intent.name != "EmergencyStopIntent":  # a stop is said bluntly
            assert any(s.startswith(("please", "could you", "can you")) for s in samples)
        assert set(intent.essentials) <= set(samples)
        first_words = {sample.split()[0] for sample in samples}
        assert len(first_words) >= 10, intent.name


def test_the_committed_model_is_inside_alexas_limits() -> None:
    model: dict[str, Any] = json.loads((ROOT / MODEL_PATH).read_text())
    check_limits(model)
    language = model["interactionModel"]["languageModel"]
    samples = [s for intent in language["intents"] for s in intent["samples"]]
    assert sum(len(s) for s in samples) <= MAX_SAMPLE_CHARS


def test_the_generator_refuses_a_slot_value_alexa_would_reject(fleet: Fleet) -> None:
    model = build_interaction_model(fleet)
    too_long = copy.deepcopy(model)
    values = too_long["interactionModel"]["languageModel"]["types"][0]["values"]
    values[0]["name"]["synonyms"].append("robot " * (MAX_SLOT_VALUE_CHARS // 6 + 1))
    with pytest.raises(ModelError, match="over 140 characters"):
        check_limits(too_long)


def test_the_generator_refuses_too_many_sample_characters(fleet: Fleet) -> None:
    # Ten intents of 240 samples of about 100 characters: over the 200,000 in all.
    wordy = tuple(
        IntentSpec(
            f"Chatter{name.title()}Intent",
            (SlotSpec("robot", "ROBOT"),),
            (
                f"{name} {'very ' * 15}(long|lengthy|wordy|verbose) (request|ask|demand|order) "
                "(one|two|three|four|five|six|seven|eight|nine|ten) "
                "(alpha|beta|gamma|delta|epsilon|zeta) for {robot}",
            ),
        )
        for name in "abcdefghij"
    )
    with pytest.raises(ModelError, match="sample utterances exceed"):
        build_interaction_model(fleet, wordy)


def test_drawn_samples_are_kept_and_read_back_by_their_spec(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path))

    def spec(*templates: str) -> IntentSpec:
        return IntentSpec("KeptIntent", (SlotSpec("zone", "ZONE"),), templates)

    # Given a spec's samples drawn once
    drawn = spec("(go|drive|head) [now] to {zone}").samples
    [kept] = (tmp_path / "vahr").glob("samples-KeptIntent-*.json")
    # Then another spec the same reads them from the cache, not drawing them again
    document = json.loads(kept.read_text())
    kept.write_text(json.dumps({**document, "samples": ["read from the cache {zone}"]}))
    assert spec("(go|drive|head) [now] to {zone}").samples == ["read from the cache {zone}"]
    # And a spec with another template draws its own
    assert "go to {zone}" not in spec("(walk|run) to {zone}").samples
    # And a damaged file is drawn again, as at first
    kept.write_text("{not json")
    assert spec("(go|drive|head) [now] to {zone}").samples == drawn
