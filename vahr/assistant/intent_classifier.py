"""Choosing the intent: a linear classifier over words with the slot values abstracted.

The classifier is `vahr.speech.text_classifier`'s (TF-IDF, a logistic regression with
balanced class weights, temperature scaling, exported and cached so that `vahr up` need not
import scikit-learn). What is particular to intents is the features: word unigrams, word
bigrams, the character n-grams inside words and the number of slot values of each type.
The training sentences are the generated samples, with each `{slot}` replaced by its type's
marker (`ROBOT`, `ZONE`), so "send ROBOT to ZONE" is learnt once for every robot and zone.
`tests/unit/local/test_intent_classifier.py` holds the features.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from vahr.speech.text_classifier import TextClassifier, ngram_features
from vahr.speech.text_classifier import fit as fit_pipeline
from vahr.speech.text_classifier import load_or_train as load_or_train_classifier

if TYPE_CHECKING:
    from pathlib import Path

# What the cached model depends on besides its data; change it with `features`, and every
# cache is invalidated.
TRAINING = "4: counts, words, bigrams, chars 3-5"
MARKERS = frozenset({"ROBOT", "ZONE"})


def features(text: str) -> list[str]:
    """The features of one abstracted utterance: how many values of each slot type it names
    (none, one, two or more), which n-grams cannot count (one robot named is rarely a
    sequential delivery, a question naming none is rarely about one robot), then words,
    bigrams and the character n-grams of words other than the markers."""
    words = text.split()
    counts = [f"k:{marker}={min(words.count(marker), 2)}" for marker in sorted(MARKERS)]
    return counts + ngram_features(words, opaque=MARKERS)


def load_or_train(
    texts: list[str], labels: list[str], cache_dir: Path | None
) -> tuple[TextClassifier, bool]:
    """The intent classifier for this training data, cached (True) or trained now (False)."""
    return load_or_train_classifier(
        texts, labels, features, name="intent-model", recipe=TRAINING, cache_dir=cache_dir
    )


def fit(texts: list[str], labels: list[str]) -> Any:
    """The scikit-learn pipeline over intent features (tests compare the export with it)."""
    return fit_pipeline(texts, labels, features)
