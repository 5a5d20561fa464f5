"""The robot's side of the local stack's room channel: a `Voice` over MQTT.

`say` renders speech and publishes it as audio on `vahr/room/{thing}/robot`; `listen`
waits for the assistant's audio on `vahr/room/{thing}/assistant` and understands it with the
same recognizer and interpreter a microphone would feed. The MQTT connection is passed in
(`RoomChannel`: publish and subscribe callables), so this module imports no MQTT library.
"""

from __future__ import annotations

import asyncio
import logging
from typing import TYPE_CHECKING, Protocol

from robot_agent.voice.port import Heard, VoiceError
from robot_agent.voice.room_message import Utterance
from vahr.protocol import topics

if TYPE_CHECKING:
    from collections.abc import Callable

    from robot_agent.voice.tts import Synthesizer
    from robot_agent.voice.understanding import Understanding

log = logging.getLogger(__name__)


class RoomChannel(Protocol):
    """The part of an MQTT client the room voice needs (vahr.local.mqtt.MqttClient fits)."""

    def publish(self, topic: str, payload: bytes) -> None: ...

    def subscribe(self, topic_filter: str, handler: Callable[[str, bytes], None]) -> None: ...


class RoomVoice:
    """A `Voice` whose speaker and microphone are MQTT topics of the room channel."""

    def __init__(
        self,
        thing: str,
        channel: RoomChannel,
        synthesizer: Synthesizer,
        understanding: Understanding,
        *,
        on_close: Callable[[], None] | None = None,
    ) -> None:
        self.thing = topics.check_thing(thing)
        self.channel = channel
        self.synthesizer = synthesizer
        self.understanding = understanding
        self._on_close = on_close
        self._loop: asyncio.AbstractEventLoop | None = None
        self._answers: asyncio.Queue[Utterance] | None = None
        self._last_said: str | None = None
        self._subscribed = False

    async def _ensure_listening(self) -> asyncio.Queue[Utterance]:
        if self._answers is None:
            self._loop = asyncio.get_running_loop()
            self._answers = asyncio.Queue()
        if not self._subscribed:
            topic = topics.room_assistant_speech(self.thing)
            await asyncio.to_thread(self.channel.subscribe, topic, self._on_message)
            self._subscribed = True
        return self._answers

    def _on_message(self, topic: str, payload: bytes) -> None:
        # Runs on the MQTT client's thread: decode here, hand over to the event loop.
        try:
            utterance = Utterance.decode(payload)
        except VoiceError as err:
            log.warning("ignoring a room message on %s: %s", topic, err)
            return
        if self._loop is not None and self._answers is not None:
            self._loop.call_soon_threadsafe(self._answers.put_nowait, utterance)

    async def say(self, text: str) -> None:
        answers = await self._ensure_listening()
        audio = await asyncio.to_thread(self.synthesizer.synthesize, text)
        # Whatever the assistant said before this question is no answer to it.
        while not answers.empty():
            answers.get_nowait()
        utterance = Utterance.new(self.thing, "robot", audio)
        try:
            await asyncio.to_thread(
                self.channel.publish, topics.room_robot_speech(self.thing), utterance.encode()
            )
        except Exception as err:  # the channel's own errors (VahrError, OSError...)
            raise VoiceError(f"cannot speak into the room: {err}") from err
        self._last_said = utterance.id

    async def listen(self, timeout_s: float) -> Heard:
        answers = await self._ensure_listening()
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
            return await asyncio.to_thread(self.understanding.hear, utterance.audio)

    def close(self) -> None:
        if self._on_close is not None:
            self._on_close()
            self._on_close = None
