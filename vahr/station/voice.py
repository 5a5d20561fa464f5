"""Push-to-talk: a WAV clip from the page in; what was heard and what the assistant answered out.

The page records while the button (or the space bar) is held and uploads 16 kHz mono
16-bit WAV; any other PCM WAV (a file a person recorded, espeak-ng's 22,050 Hz) is converted
once. The clip is checked (a WAV, at most `MAX_CLIP_S` long) and transcribed offline
by a recognizer whose vocabulary comes from the skill's interaction model
(`vocabulary.py`). Its N best transcripts are each understood by the simulator's NLU and
weighed into one understanding (`vahr.assistant.nbest`): an intent heard with too little of the
weight is not acted on, and a robot or zone the hearing is unsure of is asked about
("Zone B or zone D?") instead of acted on. A second ear (Whisper, made by the station)
transcribes the clip too when the best transcript reads as a request; a request both read
alike is acted on at once (`agreement`). The understanding goes to the assistant with the best
transcript (origin `station-voice`) and what was heard alongside.

A clip with no speech, or speech understood as nothing the skill does (out of domain,
music, noise, a ramble) changes nothing and gets `SORRY`, which says so; while the skill
waits for an answer, followed by the skill's reprompt, as an Echo does.

With the simulator in this process (`vahr up`) the weighed understanding is handed to it
as is. An assistant reached over HTTP re-reads words, so it gets the best transcript only
when the hearing is sure of every robot and zone; otherwise the station asks itself.
"""

from __future__ import annotations

import io
import logging
import threading
import time
import wave
from dataclasses import replace
from typing import TYPE_CHECKING, Any, Protocol

from vahr.assistant import (
    STOP_INTENT,
    SimulatorAssistant,
    Weighed,
    Weighing,
    agreement,
    disputed,
    request_reader,
    stop_heard,
    weigh_recognition,
)
from vahr.domain.invocation import FALLBACK_INTENT
from vahr.errors import VahrError
from vahr.speech.audio import SAMPLE_RATE, SAMPLE_WIDTH, Audio
from vahr.speech.errors import SpeechError
from vahr.station.errors import RequestError

if TYPE_CHECKING:
    from collections.abc import Callable, Mapping

    from vahr.assistant import InteractionModel, Understanding
    from vahr.plumbing.client import Assistant
    from vahr.speech.stt import Recognition, Recognizer


class Transcriber(Protocol):
    """A second recognizer: what it heard in a clip, as text (`WhisperTranscriber`)."""

    def transcribe(self, audio: Audio) -> str: ...


log = logging.getLogger(__name__)

SORRY = "Sorry, I didn't catch that. I sent nothing to the robots."
# A clip may be up to 20 s long: the page's recorder stops there.
MAX_CLIP_S = 20.0
ORIGIN = "station-voice"


def read_clip(data: bytes) -> Audio:
    """The clip as 16 kHz mono 16-bit audio, from any PCM WAV a person has (espeak-ng's
    22,050 Hz, a phone's 44.1 kHz stereo, 8-bit, float): what the page sends is read as it
    is, anything else converted once (`Audio.from_wav`, sox). RequestError 415 for a file
    that is no WAV, 400 for one that is not readable as audio, 413 for one too long."""
    if data[:4] != b"RIFF" or data[8:12] != b"WAVE":
        raise RequestError(415, "the clip is not a WAV file (push-to-talk takes a WAV of speech)")
    shape: tuple[int, int, int] | None = None
    try:
        with wave.open(io.BytesIO(data), "rb") as clip:
            shape = (clip.getnchannels(), clip.getsampwidth(), clip.getframerate())
            pcm = clip.readframes(clip.getnframes())
    except (wave.Error, EOFError, RuntimeError):
        # A float or extensible WAV, which the wave module cannot read, or a broken one (a
        # chunk whose size points past the end raises a bare RuntimeError): sox says which.
        pass
    if shape == (1, SAMPLE_WIDTH, SAMPLE_RATE):
        audio = Audio(pcm[: len(pcm) - len(pcm) % SAMPLE_WIDTH])
    else:
        try:
            audio = Audio.from_wav(data)
        except SpeechError as err:
            raise RequestError(400, f"the WAV file is not readable as audio: {err}") from err
    if audio.seconds > MAX_CLIP_S:
        raise RequestError(413, f"the clip is {audio.seconds:.1f} s; at most {MAX_CLIP_S:g} s")
    return audio


def ask_back(weighed: Weighed, slot_types: Mapping[str, str]) -> str | None:
    """The station's own question when a remote assistant cannot be given the weighed
    understanding: which value of an unsure robot or zone slot was meant; None when sure.
    `slot_types` are the intent's slots and their types."""
    slots = weighed.understanding.slots
    for value in slots.values():
        if value.alternatives and value.canonical:
            options = [value.canonical, *(name for _, name in value.alternatives)]
            return f"Did you say {' or '.join(options)}? Please say it again."
    for name in weighed.slot_confidence:
        if name not in slots:  # heard by too few of the readings to act on
            kind = slot_types.get(name, name).lower()
            return f"I'm not sure which {kind} you said. Please say it again."
    return None


class PushToTalk:
    """Recognize a clip, weigh its readings, and pass the understanding to the assistant.

    Both ears are made on first use, or ahead of it in the background with `warm_up`,
    which the station calls when a page opens: someone there may talk, and the first press
    should not wait for them, while a stack nobody talks to never builds a recognizer nor
    loads Whisper's weights. The recognizer that `vocabulary.command_recognizer` makes has
    its language model made in a child process, so the warm-up thread mostly waits, leaving
    the interpreter lock to the station's MQTT intake. The NLU is the
    simulator's when the assistant is the simulator in this process, else the one that
    ships with the package (built on first use).
    """

    def __init__(
        self,
        assistant: Assistant,
        recognizer: Callable[[], Recognizer],
        second_ear: Callable[[], Transcriber] | None = None,
    ) -> None:
        """`second_ear` makes a second recognizer (Whisper) whose transcript, where it
        agrees with the first's, is acted on at once; without it, or when it cannot be
        made (said once in the log), the N best alone decide."""
        self.assistant = assistant
        self._make = recognizer
        self._recognizer: Recognizer | None = None
        self._make_second = second_ear
        self._second: Transcriber | None = None
        self._model: InteractionModel | None = None
        self._lock = threading.Lock()
        self._second_lock = threading.Lock()
        # Whether a warm-up was started: a lock of its own, as `_lock` is held while the
        # recognizer is built (a page opening then must not wait for it).
        self._warming = False
        self._warming_lock = threading.Lock()

    def warm_up(self) -> threading.Thread | None:
        """Make the recognizer, then the second ear, in the background, once; the thread,
        or None when they are made or being made already."""
        with self._warming_lock:
            if self._warming:
                return None
            self._warming = True
        thread = threading.Thread(target=self._warm, name="station-ears", daemon=True)
        thread.start()
        return thread

    def _warm(self) -> None:
        try:
            self.recognizer()
        except (VahrError, SpeechError) as err:
            # Said once here; the first press tries again and answers with the reason.
            log.warning("push-to-talk: the recognizer could not be built: %s", err)
            return
        self.second_ear()

    def recognizer(self) -> Recognizer:
        with self._lock:
            if self._recognizer is None:
                self._recognizer = self._make()
            return self._recognizer

    def second_ear(self) -> Transcriber | None:
        """The second recognizer, made on first use; None without one (or when it could
        not be made: said once, then push-to-talk hears with the first alone)."""
        with self._second_lock:
            make, self._make_second = self._make_second, None
            if make is not None:
                try:
                    self._second = make()
                except SpeechError as err:
                    log.warning("push-to-talk hears with pocketsphinx alone: %s", err)
            return self._second

    def _listen_twice(self, audio: Audio) -> tuple[Recognition, str | None]:
        """The first recognizer's recognition, and the second ear's transcript whenever the
        first took the clip for speech: silence and noise never wait for Whisper (which
        spends seconds writing nothing for them)."""
        recognition = self.recognizer().recognize(audio)
        second = self.second_ear()
        if second is None or not recognition.accepted or not recognition.text:
            return recognition, None
        # Also when the first ear's words read as nothing the skill does: the second may
        # hear a stop the first misheard ("stop all the robots right now" heard as "all the
        # robots now"), and a stop either ear hears clearly is acted on (`stop_heard`).
        try:
            return recognition, second.transcribe(audio)
        except Exception:  # the second ear is a help: never the reason a press fails
            log.exception("push-to-talk: the second recognizer failed on a clip")
            return recognition, None

    def _reader(self, user: str | None = None) -> Callable[[str], Understanding]:
        """How the weighing reads words: in `user`'s dialog under way (the simulator in this
        process), else as a request."""
        if isinstance(self.assistant, SimulatorAssistant):
            simulator = self.assistant.simulator
            return lambda words: simulator.reading(words, user)
        return request_reader(self.model())

    def model(self) -> InteractionModel:
        if isinstance(self.assistant, SimulatorAssistant):
            return self.assistant.simulator.model
        with self._lock:
            if self._model is None:
                from vahr.assistant import InteractionModel

                self._model = InteractionModel.load()
            return self._model

    def weigh(
        self, recognition: Recognition, second: str | None = None, user: str | None = None
    ) -> Weighed:
        """The understanding of a recognition's N best (its transcript alone without); with
        the simulator in this process each reading is read in the dialog under way, so an
        answer to the skill's question ("zone b" to "Zone B or zone D?") is weighed as one.
        A second ear's transcript (`second`) read alike to the best transcript is acted on
        as heard (`agreement`); a robot or zone it heard otherwise is asked about
        (`disputed`). `user` is the Alexa account speaking (the dialog under way is
        theirs)."""
        simulator = (
            self.assistant.simulator if isinstance(self.assistant, SimulatorAssistant) else None
        )
        model, read = self.model(), self._reader(user)
        if second:
            both = agreement(model, second, recognition.text, read)
            if both is not None:
                return both
        answer = simulator.yes_or_no(recognition.text, user) if simulator else None
        if answer is not None and recognition.confidence >= Weighing().min_word_posterior:
            # A yes or a no to the skill's yes-or-no question, which said back all it
            # would do: taken from the best transcript, as the N best of one short word
            # are mostly that word with noise around it ("yes it", "yes you").
            return Weighed(answer, recognition.confidence, {}, 1)
        weighed = weigh_recognition(model, recognition, reading=read)
        if not second:
            return weighed
        if weighed.understanding.intent != STOP_INTENT:
            # A stop either ear hears clearly is acted on: stopping is always safe.
            stop = stop_heard(model, second, read)
            if stop is not None:
                return stop
        return replace(weighed, understanding=disputed(model, weighed.understanding, read(second)))

    def handle(self, wav: bytes, user: str | None = None) -> dict[str, Any]:
        """Hear a clip and, when it is understood, say it to the assistant as `user`'s
        Alexa account (the assistant's own when None)."""
        audio = read_clip(wav)
        started = time.perf_counter()
        recognition, second = self._listen_twice(audio)
        recognizer_ms = round((time.perf_counter() - started) * 1000, 1)
        heard: dict[str, Any] = {
            "transcript": recognition.text,
            "confidence": round(recognition.confidence, 3),
            "accepted": False,
            "seconds": round(audio.seconds, 2),
        }
        if second is not None:
            heard["second"] = second
        result: dict[str, Any] = {
            "heard": heard,
            "recognizer_ms": recognizer_ms,
            "understood": False,
            "speech": SORRY,
            "turn": None,
        }
        if not recognition.accepted or not recognition.text:
            return self._not_caught(result, user)
        weighed = self.weigh(recognition, second, user)
        heard["weighed"] = weighed.to_json()
        understanding = weighed.understanding
        if understanding.intent == FALLBACK_INTENT:
            return self._not_caught(result, user)
        heard["accepted"] = True
        turn = self._ask(weighed.words or recognition.text, heard, weighed, user)
        result["turn"] = turn
        if turn.get("intent") not in (None, FALLBACK_INTENT):
            result.update(understood=True, speech=turn.get("speech") or "")
        return result

    def _not_caught(self, result: dict[str, Any], user: str | None = None) -> dict[str, Any]:
        """`result` (SORRY); while the skill waits for an answer, with its reprompt after,
        as an Echo says it when it did not catch the answer ("Zone B or zone D? You can
        also say bravo or delta."): the question is still open."""
        if isinstance(self.assistant, SimulatorAssistant):
            pending = self.assistant.simulator.pending_for(user)
            if pending is not None and pending.reprompt:
                result["speech"] = f"{SORRY} {pending.reprompt}"
        return result

    def _ask(
        self, text: str, heard: dict[str, Any], weighed: Weighed, user: str | None = None
    ) -> dict[str, Any]:
        if isinstance(self.assistant, SimulatorAssistant):
            # The weighed understanding already reads an answer against the question.
            turn = self.assistant.simulator.say(
                text, origin=ORIGIN, heard=heard, understanding=weighed.understanding, user=user
            )
            return {**turn.to_json(), "utterance": text}
        intent = weighed.understanding.intent
        question = ask_back(weighed, self.model().intent_slots.get(intent, {}))
        if question is not None:
            return {"speech": question, "intent": intent, "commands": [], "utterance": text}
        return self.assistant.ask(text, origin=ORIGIN, heard=heard, user=user)
