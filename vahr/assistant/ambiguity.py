"""Which other robot or zone a misheard name could as well have been: a slot value's
alternatives, so the skill asks ("Zone B or zone D?") instead of acting on a guess.

The slot finder reads a word it does not know as the nearest word of a slot name
("charly" -> "charlie"). When another slot word is about as near, the words fit more than
one value about equally, and each such value is an alternative of the one chosen. Alexa
says so with several values in one ER_SUCCESS_MATCH resolution; the envelope does the same.

"About as near" is a margin of similarity (rapidfuzz ratio, 0-100), chosen from data: every
slot word is misheard in every way a single edit can mishear it (a letter dropped, added,
changed or two swapped), each variant is read as the finder reads it, and the margin kept
is the one whose readings score best by the rule every threshold of the NLU follows: the
most read right less three times the ones read as another word (a wrong action is worse
than asking). The variants are made from the model's own slot words, so no labelled set
is looked at, and a fleet with other names gets its own margin.
"""

from __future__ import annotations

import string
from functools import lru_cache
from typing import TYPE_CHECKING

import numpy as np
from rapidfuzz import fuzz, process

from vahr.assistant.slot_finder import FUZZY_CUTOFF

if TYPE_CHECKING:
    from collections.abc import Iterable, Iterator

    from vahr.assistant.slot_finder import SlotTypeValues

# The margins tried, in points of similarity; 0 never asks.
CANDIDATE_MARGINS = tuple(float(m) for m in range(0, 26))
# A wrong reading costs this many right ones (the rule the NLU's thresholds follow).
WRONG_COST = 3.0
# The finder leaves shorter words alone (slot_finder.SlotFinder.correct).
SHORTEST_CORRECTED = 4


def _single_edits(word: str) -> Iterator[str]:
    letters = string.ascii_lowercase
    for index in range(len(word) + 1):
        head, tail = word[:index], word[index:]
        if tail:
            yield head + tail[1:]
            for letter in letters:
                if letter != tail[0]:
                    yield head + letter + tail[1:]
        if len(tail) > 1:
            yield head + tail[1] + tail[0] + tail[2:]
        for letter in letters:
            yield head + letter + tail


@lru_cache(maxsize=8)
def calibrated_margin(slot_words: tuple[str, ...], known_words: frozenset[str]) -> float:
    """The margin that reads single-edit mishearings of `slot_words` best (see above)."""
    variants: list[str] = []
    truths: list[int] = []
    for truth, word in enumerate(slot_words):
        if len(word) < SHORTEST_CORRECTED:
            continue
        for variant in set(_single_edits(word)):
            if len(variant) >= SHORTEST_CORRECTED and variant not in known_words:
                variants.append(variant)
                truths.append(truth)
    if not variants:
        return 0.0
    scores = process.cdist(variants, list(slot_words), scorer=fuzz.ratio, workers=1)
    order = np.argsort(-scores, axis=1)
    rows = np.arange(len(variants))
    best = scores[rows, order[:, 0]]
    second = scores[rows, order[:, 1]] if len(slot_words) > 1 else np.zeros(len(variants))
    read = best >= FUZZY_CUTOFF  # below the cutoff the finder leaves the word unknown
    right_word = order[:, 0] == np.asarray(truths)
    # A second word under the cutoff is never a candidate, so it cannot make one ask.
    gap = np.where(second >= FUZZY_CUTOFF, best - second, np.inf)
    utilities = []
    for margin in CANDIDATE_MARGINS:
        acted = read & (gap >= margin) if margin > 0 else read
        utilities.append(
            float(np.sum(acted & right_word)) - WRONG_COST * float(np.sum(acted & ~right_word))
        )
    return CANDIDATE_MARGINS[int(np.argmax(utilities))]


class SlotAmbiguity:
    """Finds the values a found slot value could as well have been."""

    def __init__(self, slot_types: Iterable[SlotTypeValues], known_words: Iterable[str]) -> None:
        self._names = {t.name: dict(t.names) for t in slot_types}
        words = sorted(
            {w for names in self._names.values() for name in names for w in name.split()}
        )
        self._slot_words = tuple(words)
        self._known = frozenset(known_words)
        self._margin: float | None = None

    @property
    def margin(self) -> float:
        if self._margin is None:
            self._margin = calibrated_margin(self._slot_words, self._known | set(self._slot_words))
        return self._margin

    def alternatives(
        self,
        words: list[str],
        corrected: list[str],
        span: tuple[int, int],
        slot_type: str,
        chosen_id: str | None,
    ) -> tuple[tuple[str, str], ...]:
        """(id, canonical name) of the other values the span's misheard words fit about as
        well as the chosen one; empty when every word was heard as said."""
        names = self._names.get(slot_type, {})
        start, end = span
        found: dict[str, str] = {}
        for index in range(start, end):
            if words[index] == corrected[index]:
                continue
            candidates = process.extract(
                words[index],
                self._slot_words,
                scorer=fuzz.ratio,
                score_cutoff=FUZZY_CUTOFF,
                limit=None,
            )
            if not candidates:
                continue
            best = candidates[0][1]
            for word, score, _ in candidates:
                if word == corrected[index] or score < best - self.margin:
                    continue
                changed = [*corrected[start:index], word, *corrected[index + 1 : end]]
                value = names.get(" ".join(changed))
                if value is not None and value[0] != chosen_id:
                    found.setdefault(value[0], value[1])
        return tuple(found.items())
