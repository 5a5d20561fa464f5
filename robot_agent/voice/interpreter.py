"""Interpretation: from recognized text to sunny, rainy or unknown, and why.

`LocalInterpreter` reads the answer for the cues of `weather_answers.yaml` (sunny: "sun",
"clear skies", "warm"...; rainy: "rain", "pouring", "wet"...), so it understands phrasings
nobody listed, as long as they say the weather with words it knows. A negation at most
`negation_reach` words before a cue, with no clause break between ("no rain", "not a
single drop of rain", "it won't rain"), denies it: a denied cue says nothing, except the
cues that only count denied ("not a cloud in the sky" is sunny). It decides only when the
answer is one-sided:

- cues of one intent and none of the other: that intent;
- cues of both ("sunny now, rain later"), none, or only denied ones ("no rain today"):
  unknown, with the reason; but a side whose cues are all weak ("bright", often "right"
  misheard) or count only denied ("no clouds", said of a rainy day too) gives way to the
  other's strong ones;
- a cue in a clause of another time ("the forecast says it will be sunny next tuesday")
  says nothing of now, nor does one taken back after it in its clause ("the sun will not
  be out", "the rain has stayed away") or the sun that is no weather ("the sun sets");
- a question ("will it rain today"; a verb opens one only with its subject after it, as
  "is raining right now" is an answer whose "it" was not heard) or robot talk ("it is
  sunny, so I am delivering to zone A": an answer never mentions the robots' work):
  unknown, whatever the cues.

The words that decided (each cue and the words before it that could have denied it) are
returned as positions, so the caller can ask how sure the recognizer was of exactly those.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Protocol

from vahr.domain.text import normalize

if TYPE_CHECKING:
    from robot_agent.voice.answers import Cues, WeatherAnswers
    from robot_agent.voice.port import WeatherIntent


@dataclass(frozen=True)
class Interpretation:
    """The intent, how sure the interpreter is (0..1), the phrases that decided it, why it
    is unknown when it is, the positions of the words it rests on, and the sentence the
    answer was said in (the words up to a question that follows the cues, such as the
    assistant's "is there anything else I can help with")."""

    intent: WeatherIntent
    confidence: float
    evidence: tuple[str, ...] = ()
    reason: str = ""
    decisive: tuple[int, ...] = field(default=(), compare=False)
    sentence: str = field(default="", compare=False)


class Interpreter(Protocol):
    def interpret(self, text: str) -> Interpretation:
        """Map recognized text to an intent; anything not understood is `unknown`."""
        ...


UNKNOWN = Interpretation("unknown", 0.0, reason="nothing said")


@dataclass(frozen=True)
class _Cue:
    intent: WeatherIntent
    start: int
    end: int
    denied_by: int | None  # position of the negation, if any
    only_denied: bool  # a cue that counts only when denied

    def phrase(self, words: list[str]) -> str:
        if self.denied_by is not None and self.denied_by > self.start:  # undone after it
            return " ".join(words[self.start : self.denied_by + 1])
        first = self.denied_by if self.denied_by is not None else self.start
        return " ".join(words[first : self.end])


class LocalInterpreter:
    """Finds the cues of `weather_answers.yaml` in the text and decides on them."""

    def __init__(self, answers: WeatherAnswers) -> None:
        if answers.cues is None:
            raise ValueError("the weather answers have no cues")
        self.cues: Cues = answers.cues

    def interpret(self, text: str) -> Interpretation:
        words = normalize(text).split()
        if not words:
            return UNKNOWN
        cues = self.cues
        talk = sorted({w for w in words if w in cues.robot_talk})
        if talk:
            return Interpretation("unknown", 0.0, reason=f"robot talk ({', '.join(talk)})")
        if self._asks(words, 0) and words[1:2] != ["not"]:
            return Interpretation("unknown", 0.0, reason=f"a question ({words[0]} ...)")
        found = self._find(words)
        affirmed: dict[WeatherIntent, list[_Cue]] = {}
        denied: list[_Cue] = []
        elsewhen: list[tuple[_Cue, str]] = []
        for cue in found:
            if cue.only_denied == (cue.denied_by is not None):  # the cue says its weather
                when = self._other_time(words, cue)
                if when:
                    elsewhen.append((cue, when))
                else:
                    affirmed.setdefault(cue.intent, []).append(cue)
            elif cue.denied_by is not None:
                denied.append(cue)
        if len(affirmed) > 1:
            affirmed = self._without_weak_cues(affirmed, words)
        if len(affirmed) > 1:
            phrases = tuple(c.phrase(words) for group in affirmed.values() for c in group)
            return Interpretation("unknown", 0.0, phrases, "both sunny and rainy")
        if not affirmed:
            if elsewhen:
                phrases = tuple(f"{c.phrase(words)} ... {when}" for c, when in elsewhen)
                return Interpretation("unknown", 0.0, phrases, "the weather of another time")
            if denied:
                phrases = tuple(c.phrase(words) for c in denied)
                return Interpretation("unknown", 0.0, phrases, "the weather only denied")
            return Interpretation("unknown", 0.0, reason="no weather word")
        intent, chosen = next(iter(affirmed.items()))
        decisive = sorted({i for cue in chosen for i in self._span(words, cue)})
        evidence = tuple(dict.fromkeys(c.phrase(words) for c in chosen))
        last = max(cue.end for cue in chosen)
        end = next((i for i in range(last, len(words)) if self._asks(words, i)), None)
        sentence = " ".join(words[:end])
        return Interpretation(intent, 1.0, evidence, decisive=tuple(decisive), sentence=sentence)

    def _asks(self, words: list[str], at: int) -> bool:
        """Whether a question opens at `at`: a question word ("where", "what"), or a verb
        ("is", "will") with its subject after it ("is it raining", not "is raining right
        now", an answer whose "it" was not heard)."""
        word, after = words[at], words[at + 1 : at + 2]
        if word in self.cues.question_verbs:
            return bool(after) and after[0] in self.cues.question_subjects
        return word in self.cues.question_openers

    def _other_time(self, words: list[str], cue: _Cue) -> str:
        """The word that puts the cue's clause at another time ("sunny next tuesday", "it
        rained a lot last spring"), or "": the clause runs between clause breaks and up to
        a question that follows."""
        first = cue.start
        while first > 0 and words[first - 1] not in self.cues.clause_breaks:
            first -= 1
        last = cue.end
        while (
            last < len(words)
            and words[last] not in self.cues.clause_breaks
            and not self._asks(words, last)
        ):
            last += 1
        return next((w for w in words[first:last] if w in self.cues.other_times), "")

    def _without_weak_cues(
        self, affirmed: dict[WeatherIntent, list[_Cue]], words: list[str]
    ) -> dict[WeatherIntent, list[_Cue]]:
        """Both weathers said: the side whose cues are all weak ("bright", "warm") or only
        denied ("no clouds") drops out when the other has a strong cue; if both are weak or
        both strong, neither."""
        strong = {
            intent: [
                c
                for c in cues
                if not c.only_denied and " ".join(words[c.start : c.end]) not in self.cues.weak
            ]
            for intent, cues in affirmed.items()
        }
        standing = {intent: cues for intent, cues in strong.items() if cues}
        return {intent: affirmed[intent] for intent in standing} if len(standing) == 1 else affirmed

    def _find(self, words: list[str]) -> list[_Cue]:
        """Every cue in `words`, longest first where two overlap."""
        candidates: list[tuple[int, int, WeatherIntent, bool]] = []
        for only_denied, table in ((False, self.cues.said), (True, self.cues.denied)):
            for intent, phrases in table.items():
                for phrase in phrases:
                    size = len(phrase)
                    for start in range(len(words) - size + 1):
                        if tuple(words[start : start + size]) == phrase:
                            candidates.append((start, start + size, intent, only_denied))
        candidates.sort(key=lambda c: (c[0], -(c[1] - c[0])))
        cues: list[_Cue] = []
        taken = -1
        for start, end, intent, only_denied in candidates:
            if start < taken:
                continue
            denied_by = self._negation(words, start, since=taken)
            if denied_by is None:
                denied_by = self._undoing(words, end)
            cues.append(_Cue(intent, start, end, denied_by, only_denied))
            taken = end
        return cues

    def _negation(self, words: list[str], start: int, *, since: int) -> int | None:
        """The position of a negation that reaches the cue starting at `start`, if any.
        A negation denies the nearest cue after it only: "no rain the sun is out" denies
        the rain, not the sun (`since` is where the previous cue ended)."""
        nearest = max(-1, since - 1, start - 1 - self.cues.negation_reach)
        for position in range(start - 1, nearest, -1):
            if words[position] in self.cues.negations:
                return position
            if words[position] in self.cues.clause_breaks:
                return None
        return None

    def _undoing(self, words: list[str], end: int) -> int | None:
        """The position of words after a cue, in its clause, that undo it ("the sun will
        not be out", "the rain has stayed away", "the sun sets at seven"), if any."""
        last = min(len(words), end + self.cues.negation_reach + 2)
        for position in range(end, last):
            if words[position] in self.cues.clause_breaks:
                return None
            for phrase in self.cues.undone_after:
                if tuple(words[position : position + len(phrase)]) == phrase:
                    return position + len(phrase) - 1
        return None

    def _span(self, words: list[str], cue: _Cue) -> range:
        """The cue and the words before it that a negation would have stood among."""
        first = cue.start
        while first > 0 and cue.start - first < self.cues.negation_reach:
            if words[first - 1] in self.cues.clause_breaks:
                break
            first -= 1
        return range(first, cue.end)
