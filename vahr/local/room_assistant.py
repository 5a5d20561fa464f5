"""The local stack's room: the assistant that robots talk to by voice over the broker.

A robot's speech arrives as audio on `vahr/room/{thing}/robot`. The assistant recognizes it
with the robot's own offline recognizer, constrained to the questions robots ask (wake word
included); speech it does not recognize gets no answer, as an Echo ignores talk not meant
for it (the robot's acknowledgment, for one). A recognized question goes, without the wake
word, to `ask` (the Alexa simulator and the skill's weather intent), and the spoken answer
is synthesized and published as audio on `vahr/room/{thing}/assistant`.

Recognition and synthesis take tens of milliseconds, so they run on a worker thread, not
on the MQTT client's network thread.
"""

from __future__ import annotations

import logging
import queue
import threading
from dataclasses import dataclass
from typing import TYPE_CHECKING

from vahr.domain.invocation import INVOCATION_NAME, WAKE_WORD
from vahr.speech.room_channel import RoomChannel, Utterance

if TYPE_CHECKING:
    from collections.abc import Callable

    from vahr.protocol.link import Link
    from vahr.speech.stt import Recognizer
    from vahr.speech.tts import Synthesizer

log = logging.getLogger(__name__)

# What robots say to the assistant (normalized); the executor asks the first one.
QUESTIONS = tuple(
    f"{WAKE_WORD} ask {INVOCATION_NAME} {question}"
    for question in (
        "what the weather is",
        "what is the weather",
        "what's the weather",
        "for the weather",
        "about the weather",
        "how is the weather",
    )
)
STOP_TIMEOUT_S = 5.0


@dataclass(frozen=True)
class Exchange:
    """One question heard and answered, for logs, tests and the dashboard."""

    thing: str
    heard: str
    answer: str | None


class RoomAssistant:
    """Listens to every robot in the room and answers what it understands."""

    def __init__(
        self,
        link: Link,
        ask: Callable[[str], str | None],
        synthesizer: Synthesizer,
        recognizer: Recognizer,
        *,
        on_exchange: Callable[[Exchange], None] | None = None,
    ) -> None:
        self.room = RoomChannel(link)
        self.ask = ask
        self.synthesizer = synthesizer
        self.recognizer = recognizer
        self.on_exchange = on_exchange
        self._inbox: queue.Queue[Utterance | None] = queue.Queue(maxsize=64)
        self._worker: threading.Thread | None = None

    def start(self) -> RoomAssistant:
        self._worker = threading.Thread(target=self._serve, name="vahr-room", daemon=True)
        self._worker.start()
        self.room.hear_robots(self._on_speech)
        return self

    def stop(self) -> None:
        if self._worker is None:
            return
        self._inbox.put(None)
        self._worker.join(STOP_TIMEOUT_S)
        if self._worker.is_alive():
            log.warning("the room assistant did not stop within %s s", STOP_TIMEOUT_S)
        self._worker = None

    def __enter__(self) -> RoomAssistant:
        return self.start()

    def __exit__(self, *exc: object) -> None:
        self.stop()

    def _on_speech(self, utterance: Utterance) -> None:
        # Runs on the link's thread: queue the work for the worker.
        try:
            self._inbox.put_nowait(utterance)
        except queue.Full:
            log.warning("the room assistant is behind; dropped speech from %s", utterance.thing)

    def _serve(self) -> None:
        while True:
            utterance = self._inbox.get()
            if utterance is None:
                return
            try:
                self._answer(utterance)
            except Exception:  # one bad exchange must not silence the room
                log.exception("answering %s failed", utterance.thing)

    def _answer(self, utterance: Utterance) -> None:
        recognition = self.recognizer.recognize(utterance.audio)
        if not recognition.accepted:
            log.info("%s said something not for the assistant", utterance.thing)
            self._report(Exchange(utterance.thing, "", None))
            return
        request = recognition.text.removeprefix(WAKE_WORD).strip()
        speech = self.ask(request)
        self._report(Exchange(utterance.thing, recognition.text, speech))
        if not speech:
            return
        audio = self.synthesizer.synthesize(speech)
        self.room.speak(
            Utterance.new(utterance.thing, "assistant", audio, in_reply_to=utterance.id)
        )

    def _report(self, exchange: Exchange) -> None:
        log.info("room: %s asked %r, answered %r", exchange.thing, exchange.heard, exchange.answer)
        if self.on_exchange is not None:
            self.on_exchange(exchange)


def offline_room_assistant(
    link: Link, ask: Callable[[str], str | None], *, voice: str = "en-us+f4"
) -> RoomAssistant:
    """The room assistant with espeak-ng (a voice unlike the robots') and pocketsphinx.

    Questions are recognized without the phone-loop check (the grammar's decoys reject the
    robots' other talk), which keeps the assistant's part of an exchange near 60 ms.
    """
    from vahr.speech.stt import GrammarRecognizer
    from vahr.speech.tts import EspeakSynthesizer

    return RoomAssistant(
        link, ask, EspeakSynthesizer(voice), GrammarRecognizer(QUESTIONS, verify=False)
    )
