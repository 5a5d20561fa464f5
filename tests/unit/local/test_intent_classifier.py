"""The exported intent classifier answers exactly as the scikit-learn pipeline it came from."""

from __future__ import annotations

from collections import Counter

import pytest

from vahr.assistant.intent_classifier import features, fit
from vahr.assistant.nlu import InteractionModel
from vahr.speech.text_classifier import TextClassifier, export


@pytest.fixture(scope="module")
def training() -> tuple[list[str], list[str]]:
    # The data the shipped model is trained on (its classifier read from the models' cache)
    model = InteractionModel.load(background=True)
    texts, labels = model.training
    return texts, labels


def test_the_export_gives_sklearns_probabilities(training: tuple[list[str], list[str]]) -> None:
    # Given the pipeline fitted on every tenth generated sample of the larger intents (the
    # export does not depend on how much it learnt from, and the whole fit takes ten
    # seconds), and its plain-number export
    counts = Counter(training[1])
    kept = [
        (text, label)
        for n, (text, label) in enumerate(zip(*training, strict=True))
        if counts[label] <= 30 or n % 10 == 0
    ]
    texts, labels = [text for text, _ in kept], [label for _, label in kept]
    pipeline = fit(texts, labels)
    exported = TextClassifier(export(pipeline), features)
    # When both score utterances seen and unseen in training
    probes = [*texts[::40], "ROBOT please trundle over to ZONE", "play a song", "qwerty"]
    expected = pipeline.predict_proba(probes)
    # Then the probabilities agree to rounding error, class by class
    classes = list(pipeline.classes_)
    for probe, row in zip(probes, expected, strict=True):
        got = dict(exported.scores(probe).ranked)
        for name, probability in zip(classes, row, strict=True):
            assert got[name] == pytest.approx(probability, abs=1e-9), (probe, name)


def test_features_count_slot_values_and_skip_characters_of_markers() -> None:
    found = features("send ROBOT to ZONE")
    assert "k:ROBOT=1" in found and "k:ZONE=1" in found
    assert "w:send" in found and "b:<s> send" in found and "b:ZONE </s>" in found
    assert "c: se" in found
    assert not any(f.startswith("c:") and "ROB" in f for f in found)
