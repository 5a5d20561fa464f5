"""The room channel: speech as audio between robots and the assistant, over a `Link`.

It stands in for the air between a robot's speaker and an Echo (docs/voice.md). A robot
speaks on `vahr/room/{thing}/robot`; the assistant answers on `vahr/room/{thing}/assistant`.
Each message is one `Utterance`: who spoke, in reply to what, and the audio, as JSON with
the WAV file base64-encoded, so it is self-describing and readable with any MQTT client.
Both ends (the robot's room voice and the local assistant) use `RoomChannel`, over
whichever `Link` they have (awscrt on a robot, paho on the lab side).
"""

from __future__ import annotations

import base64
import binascii
import json
import logging
import uuid
from dataclasses import dataclass
from typing import TYPE_CHECKING, Literal

from vahr.protocol import topics
from vahr.speech.audio import Audio
from vahr.speech.errors import SpeechError

if TYPE_CHECKING:
    from collections.abc import Callable

    from vahr.protocol.link import Link

log = logging.getLogger(__name__)

Speaker = Literal["robot", "assistant"]
# 30 s of 16 kHz 16-bit audio, base64: far more than any answer, small for mosquitto.
MAX_MESSAGE_BYTES = 1_400_000


@dataclass(frozen=True)
class Utterance:
    id: str
    thing: str
    speaker: Speaker
    audio: Audio
    in_reply_to: str | None = None

    @classmethod
    def new(
        cls, thing: str, speaker: Speaker, audio: Audio, in_reply_to: str | None = None
    ) -> Utterance:
        return cls(uuid.uuid4().hex, thing, speaker, audio, in_reply_to)

    def encode(self) -> bytes:
        body = {
            "id": self.id,
            "thing": self.thing,
            "speaker": self.speaker,
            "in_reply_to": self.in_reply_to,
            "format": "wav",
            "audio": base64.b64encode(self.audio.to_wav()).decode("ascii"),
        }
        payload = json.dumps(body, separators=(",", ":")).encode()
        if len(payload) > MAX_MESSAGE_BYTES:
            raise SpeechError(f"the utterance is too long for the room channel ({len(payload)} B)")
        return payload

    @classmethod
    def decode(cls, payload: bytes) -> Utterance:
        if len(payload) > MAX_MESSAGE_BYTES:
            raise SpeechError(f"room message of {len(payload)} B is over {MAX_MESSAGE_BYTES} B")
        try:
            body = json.loads(payload)
            speaker = body["speaker"]
            if speaker not in ("robot", "assistant"):
                raise SpeechError(f"room message: speaker {speaker!r} is not robot or assistant")
            reply = body.get("in_reply_to")
            return cls(
                id=str(body["id"]),
                thing=str(body["thing"]),
                speaker=speaker,
                audio=Audio.from_wav(base64.b64decode(body["audio"], validate=True)),
                in_reply_to=None if reply is None else str(reply),
            )
        except (ValueError, KeyError, TypeError, binascii.Error, RecursionError) as err:
            raise SpeechError(f"room message is not an utterance: {err}") from err


class RoomChannel:
    """The room over a `Link`. A message that is not an utterance, or whose topic, thing
    and speaker disagree, is logged and dropped: it never reaches a handler."""

    def __init__(self, link: Link) -> None:
        self.link = link

    def speak(self, utterance: Utterance) -> None:
        """Publish `utterance` where its speaker talks (raises SpeechError if it cannot)."""
        if utterance.speaker == "robot":
            topic = topics.room_robot_speech(utterance.thing)
        else:
            topic = topics.room_assistant_speech(utterance.thing)
        payload = utterance.encode()
        try:
            self.link.publish(topic, payload)
        except Exception as err:  # the link's own errors (VahrError, OSError...)
            raise SpeechError(f"cannot speak into the room: {err}") from err

    def hear_robots(self, handler: Callable[[Utterance], None]) -> None:
        """Call `handler` with what every robot says (the assistant's side)."""
        self.link.add_route(topics.ROOM_ROBOT_SPEECH, _checked("robot", handler))

    def hear_assistant(self, thing: str, handler: Callable[[Utterance], None]) -> None:
        """Call `handler` with what the assistant says to `thing` (that robot's side)."""
        self.link.add_route(topics.room_assistant_speech(thing), _checked("assistant", handler))


def _checked(
    speaker: Speaker, handler: Callable[[Utterance], None]
) -> Callable[[str, bytes], None]:
    def on_message(topic: str, payload: bytes) -> None:
        try:
            utterance = Utterance.decode(payload)
        except SpeechError as err:
            log.warning("ignoring a room message on %s: %s", topic, err)
            return
        if topics.parse_room_topic(topic) != (utterance.thing, speaker) or (
            utterance.speaker != speaker
        ):
            log.warning("ignoring a room message on %s from %s", topic, utterance.thing)
            return
        handler(utterance)

    return on_message
