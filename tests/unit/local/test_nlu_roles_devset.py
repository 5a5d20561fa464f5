"""The development set for slot roles (roles-devset-en-US.yaml): its size, its separation
from everything the NLU learns from, and what it measured when scored once with the roles
tagger (docs/skill.md, "Slot roles"), kept as floors and ceilings."""

from __future__ import annotations

from collections import Counter

import pytest
from test_nlu_devset import TUNING_SET, generated_patterns

from vahr.assistant.background import built_in_phrases, out_of_domain_phrases
from vahr.assistant.evaluation import DEVELOPMENT_SET, LabelledSet, Report, evaluate
from vahr.assistant.nlu import InteractionModel, normalize_utterance
from vahr.assistant.simulator import strip_invocation

ROLES_SET = DEVELOPMENT_SET.with_name("roles-devset-en-US.yaml")


@pytest.fixture(scope="module")
def roles_set() -> LabelledSet:
    return LabelledSet.load(ROLES_SET)


@pytest.fixture(scope="module")
def report(roles_set: LabelledSet) -> Report:
    return evaluate(InteractionModel.load(), roles_set)


def test_the_set_is_about_roles(roles_set: LabelledSet) -> None:
    assert len(roles_set.utterances) >= 150
    intents = Counter(item.intent for item in roles_set.utterances)
    # Most of it is two robots or two zones, or a weather rule
    assert intents["SequentialDeliveryIntent"] + intents["WeatherDeliveryIntent"] >= 100
    sequences = [i for i in roles_set.utterances if i.intent == "SequentialDeliveryIntent"]
    # in both orders: the first robot named first, and named second
    said_first = Counter(
        item.slots.get("firstRobot") == "placebot1" for item in sequences if item.slots
    )
    assert said_first[True] >= 20 and said_first[False] >= 20


def test_no_sentence_is_trained_or_tuned_on(roles_set: LabelledSet) -> None:
    patterns = generated_patterns()
    background = {*out_of_domain_phrases(), *(p for v in built_in_phrases().values() for p in v)}
    seen = {
        normalize_utterance(strip_invocation("robot fleet", item.text))
        for path in (TUNING_SET, DEVELOPMENT_SET)
        for item in LabelledSet.load(path).items()
    }
    for item in roles_set.items():
        text = normalize_utterance(strip_invocation("robot fleet", item.text))
        assert not any(pattern.match(text) for pattern in patterns), item.text
        assert text not in background, item.text
        assert text not in seen, item.text


def test_roles_stay_at_the_measured_figures(report: Report) -> None:
    # Scored once with the tagger (docs/history/nlu-tuning.md): 118 of 156 right, 16 wrong; out of
    # domain 17 of 19 falling back. The English rules it replaced, on the same build: 116
    # right and 10 wrong. With the intents added since (fleet commands, task queue,
    # corrections), 16 of 19 out-of-domain sentences fall back. With readings below a roles
    # confidence of 0.5 confirmed instead of acted on, and listed values read as one by the
    # classifier: 121 right, 10 wrong, 17 asked; 17 of 19 out of domain falling back. With
    # zones closed and opened by voice (CloseZoneIntent, OpenZoneIntent), 16 of 19: one
    # remark about checking on the robots later now reads as a status question, at a
    # confidence of 0.62 (it moves nothing); the in-domain figures are unchanged.
    assert report.in_domain.counts["right"] >= 121, report.table()
    assert report.in_domain.counts["wrong"] <= 10, report.table()
    assert report.out_of_domain.counts["fallback"] >= 16, report.table()
