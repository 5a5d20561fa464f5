"""Push-to-talk: a WAV clip from the page in; what was heard and what the assistant answered out.

The page records while the button (or the space bar) is held and uploads 16 kHz mono
16-bit WAV. The clip is checked (a WAV, at most `MAX_CLIP_S` long), transcribed offline by
a recognizer whose vocabulary comes from the skill's interaction model (`vocabulary.py`),
and a transcript whose least certain word is at least `MIN_CONFIDENCE` goes to the
assistant as a request (origin `station-voice`), with what the recognizer heard alongside.
A clip with no speech, a transcript the recognizer is not sure of, or one the assistant
does not understand (its fallback intent) changes nothing and gets `SORRY`.
"""

from __future__ import annotations

import io
import threading
import time
import wave
from typing import TYPE_CHECKING, Any

from vahr.speech.audio import SAMPLE_RATE, SAMPLE_WIDTH, Audio
from vahr.station.errors import RequestError

if TYPE_CHECKING:
    from collections.abc import Callable

    from vahr.local.client import Assistant
    from vahr.speech.stt import Recognizer

SORRY = "Sorry, I didn't catch that."
MAX_CLIP_S = 20.0
# The least word posterior of a transcript passed to the assistant. Chosen by
# bench/station_hearing.py on the NLU's tuning set spoken by espeak-ng: the most requests
# understood as meant among the thresholds that act on at most 10% of out-of-domain
# sentences (docs/benchmarks.md, "Push-to-talk: spoken requests understood").
MIN_CONFIDENCE = 0.15
ORIGIN = "station-voice"
FALLBACK = "AMAZON.FallbackIntent"


def read_clip(data: bytes) -> Audio:
    """The clip as 16 kHz mono 16-bit audio; RequestError (415, 400) for anything else."""
    if data[:4] != b"RIFF" or data[8:12] != b"WAVE":
        raise RequestError(415, "the clip is not a WAV file")
    try:
        with wave.open(io.BytesIO(data), "rb") as clip:
            shape = (clip.getnchannels(), clip.getsampwidth(), clip.getframerate())
            frames = clip.getnframes()
            pcm = clip.readframes(frames)
    except (wave.Error, EOFError, RuntimeError) as err:
        # The wave module raises a bare RuntimeError for a chunk whose size points past the
        # end of the file (its chunk reader cannot seek there).
        reason = err or "a chunk is cut short"
        raise RequestError(400, f"the WAV file is not readable: {reason}") from err
    if shape != (1, SAMPLE_WIDTH, SAMPLE_RATE):
        channels, width, rate = shape
        raise RequestError(
            415,
            f"the clip is {channels} channel(s), {8 * width}-bit, {rate} Hz; "
            f"push-to-talk sends mono 16-bit {SAMPLE_RATE} Hz",
        )
    audio = Audio(pcm[: len(pcm) - len(pcm) % SAMPLE_WIDTH])
    if audio.seconds > MAX_CLIP_S:
        raise RequestError(413, f"the clip is {audio.seconds:.1f} s; at most {MAX_CLIP_S:g} s")
    return audio


class PushToTalk:
    """Recognize a clip and pass what was heard to the assistant.

    The recognizer is built on first use, or ahead of it in the background with `warm_up`
    (building one takes a moment; the first press should not wait for it).
    """

    def __init__(self, assistant: Assistant, recognizer: Callable[[], Recognizer]) -> None:
        self.assistant = assistant
        self._make = recognizer
        self._recognizer: Recognizer | None = None
        self._lock = threading.Lock()

    def warm_up(self) -> threading.Thread:
        thread = threading.Thread(target=self.recognizer, name="station-recognizer", daemon=True)
        thread.start()
        return thread

    def recognizer(self) -> Recognizer:
        with self._lock:
            if self._recognizer is None:
                self._recognizer = self._make()
            return self._recognizer

    def handle(self, wav: bytes) -> dict[str, Any]:
        audio = read_clip(wav)
        started = time.perf_counter()
        recognition = self.recognizer().recognize(audio)
        recognizer_ms = round((time.perf_counter() - started) * 1000, 1)
        accepted = recognition.accepted and recognition.confidence >= MIN_CONFIDENCE
        heard = {
            "transcript": recognition.text,
            "confidence": round(recognition.confidence, 3),
            "accepted": accepted,
            "seconds": round(audio.seconds, 2),
        }
        result: dict[str, Any] = {
            "heard": heard,
            "recognizer_ms": recognizer_ms,
            "understood": False,
            "speech": SORRY,
            "turn": None,
        }
        if not accepted or not recognition.text:
            return result
        turn = self.assistant.ask(recognition.text, origin=ORIGIN, heard=heard)
        result["turn"] = turn
        if turn.get("intent") not in (None, FALLBACK):
            result.update(understood=True, speech=turn.get("speech") or "")
        return result
