"""Speech recognition in open phrasing: pocketsphinx with a language model built from
example sentences.

A grammar hears only the sentences it lists. Here the caller gives example sentences
instead (every way of giving a weather answer it knows, and what else may be said), a
trigram model with back-off is built from them at start-up (pocketsphinx's own
`ArpaBoLM`), and the decoder may string the model's words in any order, weighted by how
the examples use them: "it is pouring" is heard although no example says it. Speech
outside the examples still comes out as the model's words, so each result carries what
is needed to judge it:

- every word's posterior probability in the decoder's word lattice: a word that the
  audio hardly supports over its rivals ("will rain" against "no rain") has a low one;
- the fit: the search path's acoustic score per frame against an unconstrained phone
  loop over the same audio (all senones scored, so both are measured against the same
  per-frame best), mapped to 0..1. Speech made of the model's words follows the phone
  loop closely; other speech, forced into those words, falls behind.

Silence never reaches the decoder (energy detection first). The caller decides what to
accept from the words and their posteriors; a fit below `min_fit` is rejected here.
"""

from __future__ import annotations

import io
import itertools
import math
import tempfile
import threading
from pathlib import Path
from typing import TYPE_CHECKING

from vahr.speech.audio import SAMPLE_RATE, SpeechDetector
from vahr.speech.errors import SpeechError
from vahr.speech.stt import NOTHING_HEARD, Alternative, HeardWord, Recognition

if TYPE_CHECKING:
    from collections.abc import Iterable

    from vahr.speech.audio import Audio

# Logistic mapping of the per-frame acoustic log-likelihood ratio of the search path
# against the phone loop (pocketsphinx log units, base 1.0001) to the fit. Set on the
# tuning set only (robot_agent/voice/data/hearing-tuning.yaml, docs/voice.md).
FIT_MIDPOINT = -12.0
FIT_SCALE = 4.0
DEFAULT_MIN_FIT = 0.5
# Readings of the N-best list kept for the caller.
N_BEST = 10
# How much of the probability mass an ARPA back-off keeps for unseen word sequences.
DISCOUNT_MASS = 0.5
_FILLERS = frozenset({"<s>", "</s>", "<sil>", "[NOISE]", "[SPEECH]", "[BREATH]", "[COUGH]"})


def arpa_model(sentences: Iterable[str]) -> str:
    """A trigram language model (ARPA text) of `sentences` (already normalized)."""
    from pocketsphinx.lm import ArpaBoLM

    corpus = "\n".join(dict.fromkeys(s for s in sentences if s.strip()))
    if not corpus:
        raise SpeechError("the language model needs at least one sentence")
    model = ArpaBoLM(text=corpus, add_start=True, discount_mass=DISCOUNT_MASS)
    model.compute()
    out = io.StringIO()
    model.write(out)
    return out.getvalue()


class LanguageModelRecognizer:
    """pocketsphinx with an n-gram model of example sentences, word posteriors and a
    phone-loop fit."""

    def __init__(
        self,
        sentences: Iterable[str],
        *,
        min_fit: float = DEFAULT_MIN_FIT,
        detector: SpeechDetector | None = None,
    ) -> None:
        from pocketsphinx import Decoder, get_model_path

        self.sentences = tuple(dict.fromkeys(sentences))
        self.min_fit = min_fit
        self.detector = detector or SpeechDetector()
        model = Path(get_model_path())
        self.vocabulary = frozenset(w for s in self.sentences for w in s.split())
        # Only the model's words from the 130,000 of the dictionary: the search is built
        # in milliseconds instead of seconds.
        pronunciations = _pronunciations(model / "en-us" / "cmudict-en-us.dict", self.vocabulary)
        missing = sorted(self.vocabulary - {line.split(" ", 1)[0] for line in pronunciations})
        if missing:
            raise SpeechError(f"words missing from the pronunciation dictionary: {missing}")
        with tempfile.TemporaryDirectory() as folder:
            dictionary = Path(folder) / "words.dict"
            dictionary.write_text("".join(pronunciations), encoding="utf-8")
            arpa = Path(folder) / "sentences.arpa"
            arpa.write_text(arpa_model(self.sentences), encoding="utf-8")
            self._decoder = Decoder(
                lm=None,
                dict=str(dictionary),
                loglevel="FATAL",
                compallsen=True,
                samprate=float(SAMPLE_RATE),
            )
            self._decoder.add_lm_file("sentences", str(arpa))
        self._decoder.add_allphone_file("phones", str(model / "en-us" / "en-us-phone.lm.bin"))
        self._logmath = self._decoder.get_logmath()
        # One decoder, one utterance at a time.
        self._lock = threading.Lock()

    def recognize(self, audio: Audio) -> Recognition:
        if not self.detector.segments(audio):
            return NOTHING_HEARD
        with self._lock:
            sentence_score = self._score_per_frame("sentences", audio)
            words = self._words()
            text = " ".join(word.text for word in words)
            if sentence_score is None or not words:
                return Recognition(text, 0.0, False, words, "nothing recognizable")
            alternatives = self._alternatives()
            phone_score = self._score_per_frame("phones", audio)
        if phone_score is None:
            return Recognition(text, 0.0, False, words, "nothing recognizable")
        ratio = sentence_score - phone_score
        self.last_ratio = ratio
        fit = round(1.0 / (1.0 + math.exp(-(ratio - FIT_MIDPOINT) / FIT_SCALE)), 3)
        if fit < self.min_fit:
            return Recognition(
                text, fit, False, words, "does not sound like these words", alternatives
            )
        return Recognition(text, fit, True, words, alternatives=alternatives)

    def _alternatives(self) -> tuple[Alternative, ...]:
        """Up to `N_BEST` distinct readings, best first, scores relative to the best."""
        found: dict[str, float] = {}
        for hypothesis in itertools.islice(self._decoder.nbest(), N_BEST * 3):
            if hypothesis.score <= 0.0:
                continue
            text = " ".join(hypothesis.hypstr.split())
            found.setdefault(text, float(self._logmath.log(hypothesis.score)))
            if len(found) >= N_BEST:
                break
        if not found:
            return ()
        best = max(found.values())
        return tuple(Alternative(text, round(score - best, 1)) for text, score in found.items())

    def _words(self) -> tuple[HeardWord, ...]:
        found = []
        for segment in self._decoder.seg():
            if segment.word in _FILLERS or segment.word.startswith("["):
                continue
            # An alternative pronunciation is reported as `word(2)`.
            found.append(HeardWord(segment.word.split("(")[0], round(float(segment.prob), 3)))
        return tuple(found)

    def _score_per_frame(self, search: str, audio: Audio) -> float | None:
        decoder = self._decoder
        decoder.activate_search(search)
        decoder.start_utt()
        decoder.process_raw(audio.pcm, full_utt=True)
        decoder.end_utt()
        hypothesis = decoder.hyp()
        frames = decoder.n_frames()
        if hypothesis is None or hypothesis.score <= 0.0 or frames == 0:
            return None
        # The binding hands the score back exponentiated; take the log again.
        return float(self._logmath.log(hypothesis.score)) / frames


def _pronunciations(dictionary: Path, words: frozenset[str]) -> list[str]:
    """The lines of `dictionary` for `words`, alternative pronunciations (`word(2)`) too."""
    with dictionary.open(encoding="utf-8") as lines:
        return [line for line in lines if line.split(" ", 1)[0].split("(")[0] in words]
