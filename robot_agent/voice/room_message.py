"""One utterance on the room channel: who spoke, in reply to what, and the audio itself.

JSON with the WAV file base64-encoded, so the message is self-describing and readable with
any MQTT client. Both ends (the robot's `RoomVoice` and the local assistant) use this model.
"""

from __future__ import annotations

import base64
import binascii
import json
import uuid
from dataclasses import dataclass
from typing import Literal

from robot_agent.voice.audio import Audio
from robot_agent.voice.port import VoiceError

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
            raise VoiceError(f"the utterance is too long for the room channel ({len(payload)} B)")
        return payload

    @classmethod
    def decode(cls, payload: bytes) -> Utterance:
        if len(payload) > MAX_MESSAGE_BYTES:
            raise VoiceError(f"room message of {len(payload)} B is over {MAX_MESSAGE_BYTES} B")
        try:
            body = json.loads(payload)
            speaker = body["speaker"]
            if speaker not in ("robot", "assistant"):
                raise VoiceError(f"room message: speaker {speaker!r} is not robot or assistant")
            reply = body.get("in_reply_to")
            return cls(
                id=str(body["id"]),
                thing=str(body["thing"]),
                speaker=speaker,
                audio=Audio.from_wav(base64.b64decode(body["audio"], validate=True)),
                in_reply_to=None if reply is None else str(reply),
            )
        except (ValueError, KeyError, TypeError, binascii.Error) as err:
            raise VoiceError(f"room message is not an utterance: {err}") from err
