"""A linear text classifier trained with scikit-learn and answered without it.

Training (scikit-learn): TF-IDF over the features an `Analyzer` draws from a text (sublinear
tf, l2-normalized); a logistic regression with balanced class weights (the classes rarely
have as many examples as each other); and temperature scaling fitted on held-out
predictions (`CalibratedClassifierCV(method="temperature", ensemble=False)`: 5-fold
out-of-fold decisions calibrate one temperature; the final regression is fitted on every
example). The regression of every example is fitted first and the others start from its
solution, which takes 40 % less time for the same optimum.

scikit-learn takes 2-3 s to import on the lab machine, more than a start-up may add. So the
fitted model is exported as plain numbers (vocabulary, idf, weights, intercepts, inverse
temperature) and cached on disk as JSON under a hash of the training data and the recipe;
answering needs only this module, and scikit-learn is imported only when the cache is cold.
Processes that want the same model at once train it once (`training_lock`).
The Alexa simulator's intent classifier (`vahr.assistant.intent_classifier`) and the
robot's sense check of what it heard (`robot_agent.voice.sense`) are both this.
`tests/unit/local/test_intent_classifier.py` (many classes) and `tests/unit/voice/
test_sense.py` (two) hold the export to scikit-learn's own probabilities.
"""

from __future__ import annotations

import contextlib
import fcntl
import math
from collections import Counter
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import msgspec

from vahr.model_cache import content_key, write_atomically

if TYPE_CHECKING:
    from collections.abc import Callable, Iterator
    from pathlib import Path

    Analyzer = Callable[[str], list[str]]

CALIBRATION_FOLDS = 5
# The learner's own part of every recipe: change `fit` or `export`, and every cache built
# with the old one is invalidated.
LEARNER = "tfidf(sublinear), logreg(balanced, newton-cg, folds started from all), T(5 folds)"


def ngram_features(words: list[str], *, opaque: frozenset[str] = frozenset()) -> list[str]:
    """Words, word pairs (with the sentence's ends) and the character 3- to 5-grams of each
    word but the `opaque` ones (placeholders whose spelling means nothing)."""
    found = [f"w:{word}" for word in words]
    padded = ["<s>", *words, "</s>"]
    found += [f"b:{first} {second}" for first, second in zip(padded, padded[1:], strict=False)]
    for word in words:
        if word in opaque:
            continue
        wrapped = f" {word} "
        for size in (3, 4, 5):
            found += [f"c:{wrapped[i : i + size]}" for i in range(len(wrapped) - size + 1)]
    return found


@dataclass(frozen=True)
class Scores:
    """Calibrated probabilities per class, best first."""

    ranked: list[tuple[str, float]]

    @property
    def best(self) -> tuple[str, float]:
        return self.ranked[0]

    def of(self, label: str) -> float:
        return dict(self.ranked).get(label, 0.0)

    def without(self, label: str) -> Scores:
        """The scores with `label` set aside and the others renormalized."""
        kept = [(name, p) for name, p in self.ranked if name != label]
        total = sum(p for _, p in kept) or 1.0
        return Scores([(name, p / total) for name, p in kept])


class TextClassifier:
    """The exported linear model: TF-IDF weights, one row of weights per feature."""

    def __init__(self, exported: dict[str, Any], analyzer: Analyzer) -> None:
        self.classes: list[str] = exported["classes"]
        self._analyzer = analyzer
        self._index: dict[str, int] = exported["vocabulary"]
        self._idf: list[float] = exported["idf"]
        self._weights: list[list[float]] = exported["weights"]
        self._intercept: list[float] = exported["intercept"]
        self._beta: float = exported["beta"]

    def vector(self, text: str) -> dict[int, float]:
        """The TF-IDF vector of `text` (sublinear tf, l2-normalized), as sklearn computes it."""
        counts = Counter(
            index for f in self._analyzer(text) if (index := self._index.get(f)) is not None
        )
        weighted = {i: (1.0 + math.log(n)) * self._idf[i] for i, n in counts.items()}
        norm = math.sqrt(sum(value * value for value in weighted.values()))
        return {i: value / norm for i, value in weighted.items()} if norm else {}

    def scores(self, text: str) -> Scores:
        decision = list(self._intercept)
        for index, value in self.vector(text).items():
            for k, weight in enumerate(self._weights[index]):
                decision[k] += value * weight
        if len(decision) == 1:
            # A regression of two classes has one decision, for the second class; the
            # temperature scaling reads it as the logits (-d, d).
            decision = [-decision[0], decision[0]]
        top = max(decision)
        exps = [math.exp(self._beta * (d - top)) for d in decision]
        total = sum(exps)
        ranked = sorted(
            ((name, e / total) for name, e in zip(self.classes, exps, strict=True)),
            key=lambda pair: pair[1],
            reverse=True,
        )
        return Scores(ranked)


def training_key(recipe: str, texts: list[str], labels: list[str]) -> str:
    """A hash of everything a trained model depends on."""
    from importlib.metadata import PackageNotFoundError, version

    try:
        learner = version("scikit-learn")
    except PackageNotFoundError:
        learner = "absent"
    return content_key([LEARNER, recipe, learner, texts, labels])


def load_or_train(
    texts: list[str],
    labels: list[str],
    analyzer: Analyzer,
    *,
    name: str,
    recipe: str,
    cache_dir: Path | None,
) -> tuple[TextClassifier, bool]:
    """The classifier for this training data, from the cache when it has it (True) or
    trained now and cached (False). `recipe` names what the features depend on besides the
    data (change the analyzer, change the recipe). A cache that cannot be read or written
    is skipped."""
    key = training_key(recipe, texts, labels)
    file = (cache_dir / f"{name}-{key[:24]}.json") if cache_dir else None
    if file is None:
        return TextClassifier(_trained(texts, labels, analyzer, key), analyzer), False
    cached = _cached(file, key)
    if cached is not None:
        return TextClassifier(cached, analyzer), True
    # Processes that want the same model at once (the robots of `vahr up` on a first start)
    # train it once: the first holds the lock while it trains, the others then read it.
    with training_lock(file):
        cached = _cached(file, key)
        if cached is not None:
            return TextClassifier(cached, analyzer), True
        exported = _trained(texts, labels, analyzer, key)
        write_atomically(file, msgspec.json.encode(exported))
    return TextClassifier(exported, analyzer), False


def _cached(file: Path, key: str) -> dict[str, Any] | None:
    try:
        exported = msgspec.json.decode(file.read_bytes())
    except (OSError, msgspec.DecodeError):
        return None
    return exported if isinstance(exported, dict) and exported.get("key") == key else None


def _trained(texts: list[str], labels: list[str], analyzer: Analyzer, key: str) -> dict[str, Any]:
    exported = export(fit(texts, labels, analyzer))
    exported["key"] = key
    return exported


@contextlib.contextmanager
def training_lock(file: Path) -> Iterator[None]:
    """Hold an exclusive lock for `file`'s training across processes (a lock file beside
    it); without a writable cache directory, no lock (each process trains its own)."""
    try:
        file.parent.mkdir(parents=True, exist_ok=True)
        handle = file.with_suffix(".lock").open("a")
    except OSError:
        yield
        return
    with handle:
        fcntl.flock(handle, fcntl.LOCK_EX)
        try:
            yield
        finally:
            fcntl.flock(handle, fcntl.LOCK_UN)


def fit(texts: list[str], labels: list[str], analyzer: Analyzer) -> Any:
    """The scikit-learn pipeline, fitted and calibrated (tests compare the export with it)."""
    from sklearn.calibration import CalibratedClassifierCV
    from sklearn.feature_extraction.text import TfidfVectorizer
    from sklearn.model_selection import StratifiedKFold
    from sklearn.pipeline import make_pipeline

    vectorizer = TfidfVectorizer(analyzer=analyzer, sublinear_tf=True)
    vectors = vectorizer.fit_transform(texts)
    # The regression of every example first, and each fold's regression (and the final one)
    # started from its solution: the loss is strictly convex, so each reaches the optimum it
    # reached from zero (to the solver's tolerance), in half the Newton steps (the intents'
    # fit: 4-5 steps a fold, not 8, and none for the final one; 17.7 s of CPU, not 30.8).
    whole = _regression().fit(vectors, labels)
    folds = StratifiedKFold(n_splits=CALIBRATION_FOLDS, shuffle=True, random_state=0)
    calibrated = CalibratedClassifierCV(
        _regression(start=whole), method="temperature", cv=folds, ensemble=False
    )
    return make_pipeline(vectorizer, calibrated.fit(vectors, labels))


def _regression(start: Any = None) -> Any:
    """The logistic regression the classifiers learn: balanced class weights, newton-cg
    (the same optimum as the default lbfgs here, ten times faster), started from the
    solution of the regression `start` when it is fitted on as many classes."""
    from sklearn.linear_model import LogisticRegression

    class StartedRegression(LogisticRegression):
        """scikit-learn's `warm_start`, seeded with another regression's solution. The
        calibration hands its folds the classes encoded as 0..n-1 in sorted order, the
        order of `start`'s own classes, so as many classes are the same classes."""

        def __init__(self, solution: tuple[Any, Any] | None = None) -> None:
            super().__init__(
                class_weight="balanced", solver="newton-cg", max_iter=1000, warm_start=True
            )
            # Plain arrays, not the estimator: scikit-learn's `clone` would unfit it.
            self.solution = solution

        def fit(self, x: Any, y: Any, sample_weight: Any = None) -> Any:
            if self.solution is not None and self.solution[0].shape[0] == _rows(y):
                self.coef_, self.intercept_ = (part.copy() for part in self.solution)
            return super().fit(x, y, sample_weight)

    return StartedRegression(None if start is None else (start.coef_, start.intercept_))


def _rows(labels: Any) -> int:
    """The rows of a regression's weights for `labels`: one per class, one for two."""
    classes = len(set(labels))
    return 1 if classes == 2 else classes


def export(pipeline: Any) -> dict[str, Any]:
    """The fitted pipeline as plain numbers (what `TextClassifier` reads)."""
    vectorizer, calibrated = pipeline[0], pipeline[1]
    [member] = calibrated.calibrated_classifiers_
    regression = member.estimator
    [temperature] = member.calibrators
    return {
        # The calibrated wrapper encodes the labels; the regression's classes are their codes.
        "classes": [str(calibrated.classes_[code]) for code in regression.classes_],
        "vocabulary": {name: int(index) for name, index in vectorizer.vocabulary_.items()},
        "idf": vectorizer.idf_.tolist(),
        "weights": regression.coef_.T.tolist(),
        "intercept": regression.intercept_.tolist(),
        "beta": float(temperature.beta_),
    }
