"""The robot's side of the room channel: a `Voice` whose speaker and microphone are the
room's MQTT topics (`vahr.speech.room_channel`), carried by the robot's own link.

`say` renders speech and speaks it into the room; `listen` waits for the assistant's answer
to that question and understands it with the same recognizer and interpreter a microphone
would feed. The link is the agent's (`Link` port), so the robot keeps one connection, as on
AWS, and this module imports no MQTT library.
"""

from __future__ import annotations

import asyncio
from typing import TYPE_CHECKING

from robot_agent.voice.port import Heard
from vahr.protocol import topics
from vahr.speech.room_channel import RoomChannel, Utterance

if TYPE_CHECKING:
    from robot_agent.voice.hearing import Hearing
    from vahr.protocol.link import Link
    from vahr.speech.tts import Synthesizer


class RoomVoice:
    """A `Voice` in the room; routes are added at once, so answers are heard from the start."""

    def __init__(
        self,
        thing: str,
        link: Link,
        synthesizer: Synthesizer,
        hearing: Hearing,
    ) -> None:
        self.thing = topics.check_thing(thing)
        self.room = RoomChannel(link)
        self.synthesizer = synthesizer
        self.hearing = hearing
        self._loop: asyncio.AbstractEventLoop | None = None
        self._answers: asyncio.Queue[Utterance] | None = None
        self._last_said: str | None = None
        self.room.hear_assistant(self.thing, self._on_answer)

    def _queue(self) -> asyncio.Queue[Utterance]:
        if self._answers is None:
            self._loop = asyncio.get_running_loop()
            self._answers = asyncio.Queue()
        return self._answers

    def _on_answer(self, utterance: Utterance) -> None:
        # May run on the link's thread: hand over to the event loop. Before the first
        # question nothing is waiting, and nothing said then answers a later one.
        if self._loop is not None and self._answers is not None:
            self._loop.call_soon_threadsafe(self._answers.put_nowait, utterance)

    async def say(self, text: str) -> None:
        answers = self._queue()
        audio = await asyncio.to_thread(self.synthesizer.synthesize, text)
        # Whatever the assistant said before this question is no answer to it.
        while not answers.empty():
            answers.get_nowait()
        utterance = Utterance.new(self.thing, "robot", audio)
        await asyncio.to_thread(self.room.speak, utterance)
        self._last_said = utterance.id

    async def listen(self, timeout_s: float) -> Heard:
        answers = self._queue()
        deadline = asyncio.get_running_loop().time() + timeout_s
        while True:
            remaining = deadline - asyncio.get_running_loop().time()
            if remaining <= 0:
                return Heard("", "unknown", 0.0)
            try:
                utterance = await asyncio.wait_for(answers.get(), remaining)
            except TimeoutError:
                return Heard("", "unknown", 0.0)
            # An answer to an earlier question (a late reply) is not this one's answer.
            if utterance.in_reply_to not in (None, self._last_said):
                continue
            return await asyncio.to_thread(self.hearing.hear, utterance.audio)
