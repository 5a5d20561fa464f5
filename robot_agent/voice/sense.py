"""The sense check: is what the robot heard an answer about the weather at all?

The interpreter reads cues, and a cue says nothing of its sense: "she has such a sunny
personality", "a baby shower", "the rainy day fund" hold cues and are no answer. So a
second opinion reads the whole sentence: a text classifier
(`vahr.speech.text_classifier`: TF-IDF of words, word pairs and character n-grams, a
logistic regression) trained on weather answers (the intents' phrasings of
`weather_answers.yaml` and the answers of `data/answer-sense.yaml`) against other speech
(its `not_answers` and the other sentences of `data/answer-sense.yaml`: weather words in
other senses, questions about the weather, other weather), each also as the robot's
recognizer heard it spoken, clean and in noise (`data/answer-sense-heard.yaml`, written by
`sense_heard`), since what it reads at run time is heard, not written. It may only veto:
a sentence the cues make sunny or rainy is unknown when the classifier finds it less than
`ANSWER_AT_LEAST` likely an answer, both as a whole and as the sentence the cues were said
in (the words up to a question that follows them). Which answer it is stays the cues' to say,
so the reason is always a cue.

Chosen on the tuning set (docs/history/voice-tuning.md): scikit-learn's default
regularization, and the threshold by the hearing's rule (the classifier's own decision,
0.5, until the eleventh round; 0.65 since the twelfth, of 0.4 to 0.8). The model is
exported and cached like the NLU's, so a robot starts without importing scikit-learn once
the cache is warm.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

from robot_agent.voice.answers import read_yaml
from vahr.domain.text import normalize
from vahr.model_cache import default_cache_dir
from vahr.speech.errors import SpeechError
from vahr.speech.text_classifier import load_or_train, ngram_features

if TYPE_CHECKING:
    from robot_agent.voice.answers import WeatherAnswers
    from vahr.speech.text_classifier import TextClassifier

SENSE_FILE = Path(__file__).with_name("data") / "answer-sense.yaml"
# The same sentences as the robot's recognizer heard them (`make sense-heard`); optional.
HEARD_FILE = SENSE_FILE.with_name("answer-sense-heard.yaml")
ANSWER, OTHER = "answer", "other"
# What the cached model depends on besides its data; change it with `features`.
RECIPE = "sense 1: words, bigrams, chars 3-5"
# How likely an answer a reading must be to stand, set on the tuning set only, by the
# hearing's rule (answers right less three times the unrelated speech accepted), of 0.4,
# 0.5, 0.55, 0.6, 0.65, 0.7 and 0.8 (docs/history/voice-tuning.md, "The twelfth round").
ANSWER_AT_LEAST = 0.65


def features(text: str) -> list[str]:
    """Words, word pairs (with the sentence's ends) and the character n-grams of words."""
    return ngram_features(text.split())


@dataclass(frozen=True)
class Sense:
    """How likely the text is an answer (0..1), and whether that is likely enough."""

    answer: float

    @property
    def is_answer(self) -> bool:
        return self.answer >= ANSWER_AT_LEAST


class SenseCheck:
    """The trained classifier of answers against other speech."""

    def __init__(self, classifier: TextClassifier) -> None:
        self.classifier = classifier

    @classmethod
    def train(
        cls,
        answers: WeatherAnswers,
        sense_file: Path = SENSE_FILE,
        *,
        heard_file: Path | None = HEARD_FILE,
        cache_dir: Path | None = None,
    ) -> SenseCheck:
        """Trained on `answers` and `sense_file`, or loaded from the cache (`cache_dir`, by
        default the user's)."""
        said, other = training_sentences(answers, sense_file, heard_file=heard_file)
        texts = [*said, *other]
        labels = [ANSWER] * len(said) + [OTHER] * len(other)
        classifier, _ = load_or_train(
            texts,
            labels,
            features,
            name="answer-sense",
            recipe=RECIPE,
            cache_dir=cache_dir or default_cache_dir(),
        )
        return cls(classifier)

    def read(self, *readings: str) -> Sense:
        """The most answer-like of `readings` of what was heard: the whole text, and the
        sentence the cues were said in (an answer stays one when the assistant goes on
        "is there anything else I can help with")."""
        texts = {normalize(text) for text in readings if text.strip()}
        best = max((self.classifier.scores(text).of(ANSWER) for text in texts), default=0.0)
        return Sense(round(best, 3))


def training_sentences(
    answers: WeatherAnswers, sense_file: Path, *, heard_file: Path | None = HEARD_FILE
) -> tuple[list[str], list[str]]:
    """(answers, other speech), normalized, without duplicates: the written sentences and,
    when `heard_file` exists, the same as the recognizer heard them. A heard text that is
    also on the other side, written or heard, is left out: "is it raining" heard as "it is
    raining" teaches nothing but noise."""
    written_said, written_other = _sentences(sense_file)
    said = [*answers.all_phrases(), *written_said]
    other = [*answers.not_answers, *written_other]
    if heard_file is not None and heard_file.exists():
        heard_said, heard_other = _sentences(heard_file)
        said_all, other_all = {*said, *heard_said}, {*other, *heard_other}
        said += [text for text in heard_said if text not in other_all]
        other += [text for text in heard_other if text not in said_all]
    return list(dict.fromkeys(said)), list(dict.fromkeys(other))


def _sentences(path: Path) -> tuple[list[str], list[str]]:
    """The normalized `answers` and `other` lists of a sense-check file."""
    document = read_yaml(path, "the sense check's sentences")
    if not isinstance(document, dict) or not all(
        isinstance(document.get(key), list) for key in ("answers", "other")
    ):
        raise SpeechError(f"{path}: expected lists 'answers' and 'other'")
    return (
        [normalize(str(s)) for s in document["answers"]],
        [normalize(str(s)) for s in document["other"]],
    )
