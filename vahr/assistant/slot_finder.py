"""Finding slot values in an utterance: the first step of the simulator's understanding.

Every name of every value of the custom slot types (ROBOT, ZONE) is looked for in the
words, the longest first. A word the model has never seen is first compared with the slot
types' own words (rapidfuzz), so a misheard "plasebot" still finds "placebot"; words the
model knows ("two", "robots") are never bent into another, since a changed number or letter
would name another robot or zone. Some spans need more than a name:

- a bare letter ("to b") is a zone only where the samples put a zone: after a word that
  comes before `{zone}` in some sample and before a word that follows one (or at an end),
  so the "a" of "deliver a package" stays a word;
- a head word of a type followed by a number, a letter or an unknown word ("robot nine",
  "zone f") is a value of that type that does not resolve, so the skill asks for it
  rather than acting on a guess;
- two names that overlap and name different values ("delivers first placebot two": "first
  placebot" is robot one, "placebot two" robot two) are one value that does not resolve:
  the words cannot say which was meant, so the skill asks rather than take the first;
  but an ordinal right after a robot's name is that robot's turn ("placebot one first,
  placebot two second"), not the start of the next name;
- a bare number or letter joined to a name by a joiner ("and", "or") names the value the
  name would with that word last ("robot one and two", "zone a or b"), so the second value
  is not lost: "stop robot one and two" stops both, not robot one alone;
- an `other` phrase followed by a word of a type's names ("the other robot", "the other
  one") is a value of that type that does not resolve by its words: which one it is
  depends on the value named before it, which `roles` settles where it can (a fleet of two).

The function words (articles, joiners, turns, the verbs of going, the `other` phrases) are
the locale's (`understanding.yaml`'s `finder`), not code's.
"""

from __future__ import annotations

from collections import defaultdict
from dataclasses import dataclass
from functools import lru_cache
from typing import TYPE_CHECKING

from rapidfuzz import fuzz, process

from vahr.domain.locale import DEFAULT_LOCALE, LocaleError
from vahr.domain.text import normalize, spell_numbers

if TYPE_CHECKING:
    from collections.abc import Iterable, Mapping

    from vahr.assistant.understanding import FinderWords

# Misheard words closer than this (rapidfuzz ratio, 0-100) to a word of a slot name are read
# as that word; below it they stay unknown.
FUZZY_CUTOFF = 75.0
# The NLU reads numbers up to twenty as words (a larger one stays digits), and never bends
# those words into a slot word: a changed number would name another robot or zone.
SPELLED_BELOW = 21


def number_words(locale: str = DEFAULT_LOCALE) -> frozenset[str]:
    """The words `locale` says the numbers up to twenty with (its `language.yaml`); none
    for a locale without language data, whose numbers stay digits."""
    try:
        return frozenset(
            spell_numbers(str(number), locale=locale) for number in range(SPELLED_BELOW)
        )
    except LocaleError:
        return frozenset()


# Remembered: a model's training normalizes its samples word by word, some 50,000 words of
# a few hundred (0.6 s of CPU at every start without it).
@lru_cache(maxsize=1 << 16)
def normalize_utterance(text: str, locale: str = DEFAULT_LOCALE) -> str:
    """An utterance as the NLU reads it: `vahr.domain.text.normalize`d, with numbers to
    twenty in the locale's words: "Send PlaceBot-1 to Zone B!" -> "send placebot one to
    zone b" ("placebot eins" in de-DE); digits stay for a locale without language data."""
    try:
        return spell_numbers(normalize(text), below=SPELLED_BELOW, locale=locale)
    except LocaleError:
        return normalize(text)


@dataclass(frozen=True)
class SlotMatch:
    """A span of words naming a value of a slot type (`id` None when it does not resolve)."""

    type: str
    start: int
    end: int
    spoken: str
    id: str | None
    canonical: str | None
    # 100 for an exact name, lower when a misheard word was read as a name's word.
    similarity: float
    # "the other robot": a value named by the one named before it (`roles` resolves it).
    refers_to_other: bool = False


@dataclass(frozen=True)
class SlotTypeValues:
    """One custom slot type: normalized name -> (value id, canonical name)."""

    name: str
    names: Mapping[str, tuple[str, str]]


class SlotFinder:
    """Finds the slot values in normalized words, given the slot types and the samples."""

    def __init__(
        self,
        slot_types: Iterable[SlotTypeValues],
        samples: Iterable[tuple[str, Mapping[str, str]]],
        known_words: Iterable[str],
        function_words: FinderWords,
        locale: str = DEFAULT_LOCALE,
    ) -> None:
        """`samples` are (sample text, its slot name -> type); `known_words` are every word
        the classifier was trained on, which are never corrected into slot words;
        `function_words` are the locale's (`understanding.yaml`), and its number words its
        `language.yaml`'s."""
        self._numbers = number_words(locale)
        articles = frozenset(function_words.articles)
        self._joiners = frozenset(function_words.joiners)
        self._turns = frozenset(function_words.turns)
        self._going = frozenset(function_words.going)
        self._other = [tuple(phrase.split()) for phrase in function_words.other]
        # The words that may follow an `other` phrase: any word of the type's names.
        self._other_heads: dict[str, str] = {}
        self._names: dict[tuple[str, ...], list[tuple[str, str, str]]] = defaultdict(list)
        self._heads: dict[str, str] = {}
        slot_words: set[str] = set()
        for slot_type in slot_types:
            owners: dict[str, set[str]] = defaultdict(set)
            for name, (value_id, canonical) in slot_type.names.items():
                name_words = tuple(name.split())
                self._names[name_words].append((slot_type.name, value_id, canonical))
                slot_words.update(name_words)
                if len(name_words) > 1:
                    owners[name_words[-2]].add(value_id)
                for word in name_words:
                    self._other_heads.setdefault(word, slot_type.name)
            # The word right before what tells values apart ("robot" one, "zone" a), when
            # several values share it, names the type ("drop" of "drop zone a" does not).
            for word, ids in owners.items():
                if len(ids) > 1 and word not in articles:
                    self._heads.setdefault(word, slot_type.name)
        self._longest = max((len(words) for words in self._names), default=1)
        self._slot_words = sorted(slot_words)
        self._before: dict[str, set[str]] = defaultdict(set)
        self._after: dict[str, set[str]] = defaultdict(set)
        sample_words: set[str] = set()
        for sample, types in samples:
            words = sample.split()
            for index, word in enumerate(words):
                slot = types.get(word[1:-1]) if word.startswith("{") else None
                if slot is None:
                    sample_words.add(word)
                    continue
                if index > 0 and not words[index - 1].startswith("{"):
                    self._before[slot].add(words[index - 1])
                if index + 1 < len(words) and not words[index + 1].startswith("{"):
                    self._after[slot].add(words[index + 1])
        self._known = frozenset({*known_words, *sample_words, *slot_words, *self._numbers})

    def correct(self, words: list[str]) -> tuple[list[str], list[float]]:
        """The words with misheard slot words corrected, and each word's similarity."""
        corrected: list[str] = []
        similarity: list[float] = []
        for word in words:
            if word in self._known or len(word) < 4:
                corrected.append(word)
                similarity.append(100.0)
                continue
            best = process.extractOne(
                word, self._slot_words, scorer=fuzz.ratio, score_cutoff=FUZZY_CUTOFF
            )
            if best is None:
                corrected.append(word)
                similarity.append(100.0)
            else:
                corrected.append(best[0])
                similarity.append(float(best[1]))
        return corrected, similarity

    def find(self, words: list[str]) -> list[SlotMatch]:
        """The slot values in `words` (normalized), left to right, never overlapping."""
        corrected, similarity = self.correct(words)
        found: list[SlotMatch] = []
        index = 0
        while index < len(corrected):
            match = (
                self._name_at(corrected, words, similarity, index)
                or self._unknown_at(corrected, words, index)
                or self._other_at(words, index)
            )
            if match is None:
                index += 1
                continue
            if (
                found
                and self._right_after(found[-1], match.start, words)
                and words[match.start] in self._turns
            ):
                # "placebot one first placebot two": the ordinal is the first robot's turn,
                # not the start of "first placebot" (which names another robot than the
                # name it runs into; "second placebot two" is one name).
                after = self._name_at(corrected, words, similarity, match.start + 1)
                if after is not None and after.end > match.end and after.id != match.id:
                    match = after
            found.append(self._unless_overlapped(match, corrected, words, similarity))
            found += self._elided_after(found[-1], corrected, words, similarity)
            index = found[-1].end
        return found

    def _elided_after(
        self, match: SlotMatch, corrected: list[str], words: list[str], similarity: list[float]
    ) -> list[SlotMatch]:
        """The values named after `match` by their last word alone: "two" in "robot one
        and two" (the name's other words left out, as people do in a list)."""
        name = tuple(corrected[match.start : match.end])
        if match.id is None or len(name) < 2:
            return []
        found: list[SlotMatch] = []
        index = match.end
        while index + 1 < len(corrected) and corrected[index] in self._joiners:
            word = corrected[index + 1]
            owners = self._names.get((*name[:-1], word), [])
            value = next(((i, c) for t, i, c in owners if t == match.type), None)
            if value is None:
                break
            found.append(
                SlotMatch(
                    type=match.type,
                    start=index + 1,
                    end=index + 2,
                    spoken=words[index + 1],
                    id=value[0],
                    canonical=value[1],
                    similarity=similarity[index + 1],
                )
            )
            index += 2
        return found

    def _unless_overlapped(
        self, match: SlotMatch, corrected: list[str], words: list[str], similarity: list[float]
    ) -> SlotMatch:
        """`match`, or an unresolved value over both when a name starting inside it runs on
        past its end and names another value ("first placebot two")."""
        for start in range(match.start + 1, match.end):
            other = self._name_at(corrected, words, similarity, start)
            if other is None or other.end <= match.end or other.type != match.type:
                continue
            if other.id == match.id:
                continue
            return SlotMatch(
                type=match.type,
                start=match.start,
                end=other.end,
                spoken=" ".join(words[match.start : other.end]),
                id=None,
                canonical=None,
                similarity=100.0,
            )
        return match

    def _name_at(
        self, corrected: list[str], words: list[str], similarity: list[float], start: int
    ) -> SlotMatch | None:
        for length in range(min(self._longest, len(corrected) - start), 0, -1):
            end = start + length
            owners = self._names.get(tuple(corrected[start:end]))
            if not owners:
                continue
            for type_name, value_id, canonical in owners:
                if length == 1 and len(corrected[start]) == 1:
                    if not self._in_slot_context(type_name, corrected, start, end):
                        continue
                return SlotMatch(
                    type=type_name,
                    start=start,
                    end=end,
                    spoken=" ".join(words[start:end]),
                    id=value_id,
                    canonical=canonical,
                    similarity=min(similarity[start:end]),
                )
        return None

    def _in_slot_context(self, type_name: str, words: list[str], start: int, end: int) -> bool:
        before_ok = start == 0 or words[start - 1] in self._before[type_name]
        after_ok = end == len(words) or words[end] in self._after[type_name]
        return before_ok and after_ok

    def _other_at(self, words: list[str], start: int) -> SlotMatch | None:
        """An `other` phrase and a word of a type's names at `start` ("the other robot"), as
        a value of that type that does not resolve by its words."""
        for phrase in self._other:
            end = start + len(phrase) + 1
            if tuple(words[start : end - 1]) != phrase or end > len(words):
                continue
            type_name = self._other_heads.get(words[end - 1])
            if type_name is not None:
                spoken = " ".join(words[start:end])
                return SlotMatch(type_name, start, end, spoken, None, None, 100.0, True)
        return None

    def _right_after(self, previous: SlotMatch, start: int, words: list[str]) -> bool:
        """Whether `start` follows `previous` at once, or after a verb of going ("goes")."""
        between = words[previous.end : start]
        return not between or (len(between) == 1 and between[0] in self._going)

    def _unknown_at(self, corrected: list[str], words: list[str], start: int) -> SlotMatch | None:
        type_name = self._heads.get(corrected[start])
        if type_name is None or start + 1 >= len(corrected):
            return None
        following = corrected[start + 1]
        if not (following in self._numbers or len(following) == 1 or following not in self._known):
            return None
        return SlotMatch(
            type=type_name,
            start=start,
            end=start + 2,
            spoken=" ".join(words[start : start + 2]),
            id=None,
            canonical=None,
            similarity=100.0,
        )
