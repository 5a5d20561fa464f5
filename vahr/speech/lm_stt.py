"""Speech recognition in open phrasing: pocketsphinx with a language model built from
example sentences.

A grammar hears only the sentences it lists. Here the caller gives example sentences
instead (every way of giving a weather answer it knows, and what else may be said), a
trigram model with back-off is built from them at start-up (pocketsphinx's own
`ArpaBoLM`), and the decoder may string the model's words in any order, weighted by how
the examples use them: "it is pouring" is heard although no example says it. Speech
outside the examples still comes out as the model's words, so each word carries its
posterior probability in the decoder's word lattice: a word the audio hardly supports
over its rivals ("will rain" against "no rain") has a low one, and the caller decides
what to trust from the words that matter to it.

Speech about something else is heard as the nearest words the model knows, so the model
also knows the most frequent words of everyday English (`background_words`, taken from
pocketsphinx's general language model at start-up): "play the radio" is then heard as
that, not as "play the rainy".

Words the pronunciation dictionary lacks (made-up robot names such as "placebot") get the
pronunciations `vahr.speech.pronounce` guesses; only a word with no guess at all is an
error.

A phone-loop likelihood ratio, as `GrammarRecognizer` uses, was measured here too and
dropped: with a back-off model, answers and unrelated speech scored alike (tuning set,
docs/history/voice-tuning.md), and it doubled the time. Silence never reaches the decoder (energy
detection first).

Beside the best transcript the recognizer gives its N best (`Recognition.hypotheses`,
from the decoder's word lattice, each distinct transcript once with its best path score),
so a caller can weigh what each reading would mean: "zone b" and "zone d" a few points
apart is a question to ask, not an action.

Building the model is pure Python (`ArpaBoLM`) and, for words the dictionary lacks, one
espeak-ng call each: about a minute for the station's sentences with a fleet of 1,000
robots. A caller that must not hold its interpreter lock that long (the station, whose MQTT
intake needs it) builds the model with `cached_language_model` in a child process
(`in_child_process`) and hands the finished `LanguageModel` to the recognizer, which then
only loads it into the decoder. The cache keeps a built model on disk, keyed by a hash of
everything it is built from; reading it back (`read_cached_language_model`) is quick enough
for any caller's own process.
"""

from __future__ import annotations

import hashlib
import io
import itertools
import pickle
import shutil
import signal
import subprocess
import sys
import tempfile
import threading
from collections import Counter
from importlib.metadata import PackageNotFoundError, version
from pathlib import Path
from typing import TYPE_CHECKING, Any, TypeVar

import msgspec

from vahr.model_cache import content_key, write_atomically
from vahr.speech.audio import SAMPLE_RATE, SpeechDetector
from vahr.speech.errors import SpeechError
from vahr.speech.pronounce import guesses
from vahr.speech.stt import (
    NOTHING_HEARD,
    HeardWord,
    Hypothesis,
    Recognition,
    adapted_to,
    utterance,
)

if TYPE_CHECKING:
    from collections.abc import Callable, Iterable, Sequence

    from vahr.speech.audio import Audio

Built = TypeVar("Built")

# How much of the probability mass an ARPA back-off keeps for unseen word sequences.
DISCOUNT_MASS = 0.5
# The lattice paths read for the N best: many differ only in a filler or a pronunciation,
# so 40 paths give about 10 distinct transcripts.
NBEST_PATHS = 40
MAX_HYPOTHESES = 10
_FILLERS = frozenset({"<s>", "</s>", "<sil>", "[NOISE]", "[SPEECH]", "[BREATH]", "[COUGH]"})
# The language models the cache keeps, newest first (one per fleet and interaction model).
MODELS_KEPT = 8
# What a built model depends on besides its sentences, background words and the libraries'
# versions (in the cache key): change how a model is built, change the recipe.
MODEL_RECIPE = f"ArpaBoLM trigram, discount {DISCOUNT_MASS}; cmudict lines; pronounce.guesses"


class LanguageModel(msgspec.Struct, frozen=True):
    """What the decoder loads: a trigram model (ARPA text) and the pronunciation
    dictionary's lines for each of its words (guessed ones too)."""

    arpa: str
    dictionary: str

    @property
    def words(self) -> frozenset[str]:
        """The model's words (each has one dictionary line or more)."""
        return frozenset(
            line.split(" ", 1)[0].split("(")[0] for line in self.dictionary.splitlines() if line
        )


class _CachedModel(msgspec.Struct, frozen=True):
    """A language model as the cache keeps it: with its key, and a digest of its text so
    that a file damaged in place is noticed before the decoder reads it."""

    key: str
    digest: str
    model: LanguageModel


def arpa_model(sentences: Iterable[str]) -> str:
    """A trigram language model (ARPA text) of `sentences` (already normalized)."""
    from pocketsphinx.lm import ArpaBoLM

    class CountedArpaBoLM(ArpaBoLM):
        """`ArpaBoLM` reading a corpus of normalized sentences with `Counter`s: the same
        counts in the same order, so the same model to the byte, in a third of the time
        (its own `read_corpus` first strips a transcript's trailing "(file id)" from each
        line with a backtracking regular expression, half its time on the station's 185,000
        sentences; normalized sentences have no parentheses)."""

        def read_corpus(self, infile: Iterable[str]) -> None:
            unigrams: Counter[str] = Counter()
            bigrams: Counter[tuple[str, str]] = Counter()
            trigrams: Counter[tuple[str, str, str]] = Counter()
            for line in infile:
                words = ["<s>", *line.split(), "</s>"]
                unigrams.update(words)
                bigrams.update(itertools.pairwise(words))
                trigrams.update(zip(words, words[1:], words[2:], strict=False))
            for word, count in unigrams.items():
                self.grams_1[word] += count
            for (first, second), count in bigrams.items():
                self.grams_2[first][second] += count
            for (first, second, third), count in trigrams.items():
                self.grams_3[first][second][third] += count

    corpus = "\n".join(dict.fromkeys(s for s in sentences if s.strip()))
    if not corpus:
        raise SpeechError("the language model needs at least one sentence")
    reader = ArpaBoLM if "(" in corpus else CountedArpaBoLM
    model = reader(text=corpus, add_start=True, discount_mass=DISCOUNT_MASS)
    model.compute()
    out = io.StringIO()
    model.write(out)
    return out.getvalue()


def build_language_model(sentences: Iterable[str], background_words: int = 0) -> LanguageModel:
    """The model of `sentences` (normalized) and of the `background_words` commonest English
    words, built in this process."""
    examples = tuple(dict.fromkeys(sentences))
    entries = dictionary_entries()
    # Each background word is a sentence of its own: known, but in no example's context.
    background = (
        common_words(background_words, (e for e, _ in entries if "(" not in e))
        if background_words
        else []
    )
    vocabulary = frozenset(w for s in (*examples, *background) for w in s.split())
    # Only the model's words from the dictionary: the search is built in milliseconds
    # instead of seconds.
    pronunciations = _pronunciations(entries, vocabulary)
    missing = sorted(vocabulary - {line.split(" ", 1)[0] for line in pronunciations})
    if missing:
        pronunciations += _guessed(entries, missing)
    return LanguageModel(arpa_model([*examples, *background]), "".join(pronunciations))


def model_key(sentences: Sequence[str], background_words: int = 0) -> str:
    """The hash of everything a model is built from: the sentences, the background words,
    the recipe, and the versions of pocketsphinx (its dictionary, `ArpaBoLM`) and of
    espeak-ng (the guessed pronunciations)."""
    try:
        library = version("pocketsphinx")
    except PackageNotFoundError:
        library = "absent"
    built_from = [MODEL_RECIPE, library, _espeak_version(), background_words, list(sentences)]
    return content_key(built_from)


def cached_language_model(
    sentences: Iterable[str], background_words: int = 0, *, cache_dir: Path | None
) -> tuple[LanguageModel, bool]:
    """The model of `sentences`, from the cache in `cache_dir` when it holds it (True) or
    built now and cached (False). A cache file that cannot be read, does not decode or does
    not match its digest is built again and overwritten; one that cannot be written is
    skipped. `cache_dir=None` keeps nothing on disk."""
    examples = tuple(dict.fromkeys(sentences))
    file, key = _model_file(examples, background_words, cache_dir)
    if file is not None:
        cached = _read_cached(file, key)
        if cached is not None:
            return cached, True
    model = build_language_model(examples, background_words)
    if file is not None:
        _write_cached(file, key, model)
    return model, False


def read_cached_language_model(
    sentences: Iterable[str], background_words: int = 0, *, cache_dir: Path
) -> LanguageModel | None:
    """The model of `sentences` if the cache in `cache_dir` holds it, else None (nothing
    is built)."""
    file, key = _model_file(tuple(dict.fromkeys(sentences)), background_words, cache_dir)
    return _read_cached(file, key) if file is not None else None


def _model_file(
    examples: tuple[str, ...], background_words: int, cache_dir: Path | None
) -> tuple[Path | None, str]:
    key = model_key(examples, background_words)
    return (cache_dir / f"language-model-{key[:24]}.json" if cache_dir else None), key


def _digest(model: LanguageModel) -> str:
    text = hashlib.sha256(model.arpa.encode())
    text.update(b"\0")
    text.update(model.dictionary.encode())
    return text.hexdigest()


def _read_cached(file: Path, key: str) -> LanguageModel | None:
    try:
        cached = msgspec.json.decode(file.read_bytes(), type=_CachedModel)
    except (OSError, msgspec.DecodeError):
        return None
    if cached.key != key or cached.digest != _digest(cached.model):
        return None
    return cached.model


def _write_cached(file: Path, key: str, model: LanguageModel) -> None:
    if write_atomically(file, msgspec.json.encode(_CachedModel(key, _digest(model), model))):
        _forget_oldest(file.parent)


def _forget_oldest(folder: Path) -> None:
    """Remove all but the `MODELS_KEPT` newest models: a 1,000-robot fleet's is 6 MB, and
    every change of the interaction model or the fleet writes another."""
    try:
        stamped = sorted(
            ((f.stat().st_mtime_ns, f) for f in folder.glob("language-model-*.json")),
            reverse=True,
        )
        for _, old in stamped[MODELS_KEPT:]:
            old.unlink(missing_ok=True)
    except OSError:
        pass  # another start removed it first, or the folder is not ours to tidy


def _espeak_version() -> str:
    executable = shutil.which("espeak-ng")
    if executable is None:
        return "absent"
    try:
        done = subprocess.run(
            [executable, "--version"], capture_output=True, text=True, timeout=10, check=False
        )
    except (OSError, subprocess.TimeoutExpired):
        return "unknown"
    return done.stdout.strip()


def in_child_process(function: Callable[..., Built], *args: Any) -> Built:
    """`function(*args)` run in a fresh interpreter and its result sent back, so that this
    process keeps its interpreter lock meanwhile. `function` (importable by name) and its
    arguments must pickle; an error it raises is raised here. The child is tied to the
    calling thread's life (`vahr.lifeline`): it gets SIGTERM when that ends, SIGKILL of this
    process included.

    Not multiprocessing's spawn: its child imports the caller's main module again, which
    fails in a script without a main guard and costs the station's imports twice."""
    from vahr.lifeline import lifeline_command

    command = [sys.executable, "-c", f"from {__name__} import _child_main; _child_main()"]
    # The import path first, on its own: unpickling `function` imports its module.
    request = pickle.dumps(sys.path) + pickle.dumps(
        (function, args), protocol=pickle.HIGHEST_PROTOCOL
    )
    try:
        child = subprocess.Popen(
            lifeline_command(command, signal.SIGTERM),
            stdin=subprocess.PIPE,
            stdout=subprocess.PIPE,
        )
    except OSError as err:
        raise SpeechError(f"cannot start a process for the language model: {err}") from err
    # communicate() waits in select() without the interpreter lock.
    answer, _ = child.communicate(request)
    try:
        succeeded, value = pickle.loads(answer)  # noqa: S301 - our own child's answer
    except (pickle.UnpicklingError, EOFError, ValueError, TypeError) as err:
        raise SpeechError(
            f"the process building the language model ended without one "
            f"(exit code {child.returncode})"
        ) from err
    if not succeeded:
        raise value
    built: Built = value
    return built


def _child_main() -> None:
    """The child's side of `in_child_process`: a pickled call on stdin, its pickled outcome
    on stdout (anything the call prints goes to stderr)."""
    answer = sys.stdout.buffer
    sys.stdout = sys.stderr
    request = io.BytesIO(sys.stdin.buffer.read())
    sys.path[:] = pickle.load(request)  # noqa: S301 - from our parent
    function, args = pickle.load(request)  # noqa: S301
    try:
        outcome: tuple[bool, Any] = (True, function(*args))
    except Exception as err:  # noqa: BLE001 - any failure goes back to the caller
        outcome = (False, err)
    try:
        message = pickle.dumps(outcome, protocol=pickle.HIGHEST_PROTOCOL)
    except Exception as err:  # noqa: BLE001 - pickle raises several kinds
        failure = SpeechError(f"the language model could not be sent back: {err}")
        message = pickle.dumps((False, failure))
    answer.write(message)
    answer.flush()


class LanguageModelRecognizer:
    """pocketsphinx with an n-gram model of example sentences, and word posteriors."""

    def __init__(
        self,
        sentences: Iterable[str],
        *,
        detector: SpeechDetector | None = None,
        adaptation: Path | None = None,
        background_words: int = 0,
        nbest: bool = False,
        model: LanguageModel | None = None,
    ) -> None:
        """`model`, when given, is the one built from `sentences` and `background_words`
        (`cached_language_model`, maybe in another process); without it the model is built
        here."""
        from pocketsphinx import Decoder

        # The N best cost an A* search of the lattice per utterance (about a quarter more
        # time): only a caller that weighs them (push-to-talk) asks for them.
        self.nbest = nbest
        self.sentences = tuple(dict.fromkeys(sentences))
        self.detector = detector or SpeechDetector()
        self.model = model or build_language_model(self.sentences, background_words)
        self.vocabulary = self.model.words
        with tempfile.TemporaryDirectory() as folder:
            dictionary = Path(folder) / "words.dict"
            dictionary.write_text(self.model.dictionary, encoding="utf-8")
            arpa = Path(folder) / "sentences.arpa"
            arpa.write_text(self.model.arpa, encoding="utf-8")
            # No second (flat) pass: it doubled the time and changed no result on the
            # tuning set.
            self._decoder = Decoder(
                lm=str(arpa),
                dict=str(dictionary),
                loglevel="FATAL",
                fwdflat=False,
                samprate=float(SAMPLE_RATE),
                **adapted_to(adaptation),
            )
        # One decoder, one utterance at a time.
        self._lock = threading.Lock()

    def recognize(self, audio: Audio) -> Recognition:
        if not self.detector.segments(audio):
            return NOTHING_HEARD
        with self._lock:
            decoder = self._decoder
            with utterance(decoder):
                decoder.process_raw(audio.pcm, full_utt=True)
            words = self._words() if decoder.hyp() is not None else ()
            hypotheses = self._nbest() if words and self.nbest else ()
        if not words:
            return Recognition("", 0.0, False, reason="nothing recognizable")
        text = " ".join(word.text for word in words)
        # The confidence of the whole is that of its least certain word.
        confidence = min(word.posterior for word in words)
        return Recognition(text, confidence, True, words, hypotheses=hypotheses)

    def _nbest(self) -> tuple[Hypothesis, ...]:
        """The distinct transcripts among the lattice's best paths, best first; the best
        path's own transcript leads even when the A* search scores it lower."""
        decoder = self._decoder
        logmath = decoder.get_logmath()
        best: dict[str, float] = {}
        best_text = _clean(decoder.hyp().hypstr)
        for found in itertools.islice(decoder.nbest(), NBEST_PATHS):
            if found is None:
                break  # the A* search ran out of paths (a clip of a word or two)
            if found.score <= 0.0:
                continue
            text = _clean(found.hypstr)
            # The binding hands the score back exponentiated; take the log again.
            score = float(logmath.log(found.score))
            if text and score > best.get(text, float("-inf")):
                best[text] = score
        ranked = sorted(best.items(), key=lambda item: -item[1])
        if best_text and best_text not in best:
            top = ranked[0][1] if ranked else 0.0
            ranked.insert(0, (best_text, top))
        return tuple(Hypothesis(text, score) for text, score in ranked[:MAX_HYPOTHESES])

    def _words(self) -> tuple[HeardWord, ...]:
        found = []
        for segment in self._decoder.seg():
            if segment.word in _FILLERS or segment.word.startswith("["):
                continue
            # An alternative pronunciation is reported as `word(2)`.
            found.append(HeardWord(segment.word.split("(")[0], round(float(segment.prob), 3)))
        return tuple(found)


def _clean(transcript: str) -> str:
    """A transcript without fillers and pronunciation marks (`word(2)`)."""
    return " ".join(
        word.split("(")[0]
        for word in transcript.split()
        if word not in _FILLERS and not word.startswith("[")
    )


def dictionary_entries() -> list[tuple[str, str]]:
    """The 130,000 entries of pocketsphinx's US English pronunciation dictionary, read once
    per call: (entry, phones), `word(2)` entries being a word's other pronunciations."""
    from pocketsphinx import get_model_path

    dictionary = Path(get_model_path()) / "en-us" / "cmudict-en-us.dict"
    return [
        (entry, phones)
        for line in dictionary.read_text(encoding="utf-8").splitlines()
        for entry, _, phones in [line.partition(" ")]
    ]


def common_words(count: int, candidates: Iterable[str]) -> list[str]:
    """The `count` of `candidates` most frequent in pocketsphinx's general US English
    language model (by their unigram probability), most frequent first."""
    from pocketsphinx import Config, LogMath, NGramModel, get_model_path

    model = Path(get_model_path()) / "en-us" / "en-us.lm.bin"
    general = NGramModel(Config(), LogMath(), str(model))
    # Sorted by word first so that ties come out the same on every run.
    return sorted(sorted(set(candidates)), key=lambda word: -general.prob([word]))[:count]


def _pronunciations(entries: list[tuple[str, str]], words: frozenset[str]) -> list[str]:
    """The dictionary lines for `words`, alternative pronunciations (`word(2)`) too."""
    return [f"{entry} {phones}\n" for entry, phones in entries if entry.split("(")[0] in words]


def _guessed(entries: list[tuple[str, str]], words: list[str]) -> list[str]:
    """Dictionary lines for words the dictionary lacks, from `pronounce.guesses` (a made-up
    word may be two dictionary words run together, so the whole dictionary is looked in)."""
    first: dict[str, str] = {}
    for entry, phones in entries:
        if "(" not in entry:
            first.setdefault(entry, phones.strip())
    found = []
    for word in words:
        readings = guesses(word, first.get)
        if not readings:
            raise SpeechError(f"no pronunciation for {word!r}: not a dictionary word")
        found += [
            f"{word if index == 0 else f'{word}({index + 1})'} {phones}\n"
            for index, phones in enumerate(readings)
        ]
    return found
