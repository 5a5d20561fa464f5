"""The room channel's wire format: topics and the utterance message."""

from __future__ import annotations

import base64
import json

import pytest

from vahr.protocol import topics
from vahr.speech.audio import Audio
from vahr.speech.errors import SpeechError
from vahr.speech.room_channel import MAX_MESSAGE_BYTES, Utterance


def test_room_topics_are_built_and_parsed_in_one_place() -> None:
    assert topics.room_robot_speech("placebot1") == "vahr/room/placebot1/robot"
    assert topics.room_assistant_speech("placebot1") == "vahr/room/placebot1/assistant"
    assert topics.parse_room_topic("vahr/room/placebot2/robot") == ("placebot2", "robot")
    assert topics.parse_room_topic("vahr/room/placebot2/echo") is None
    with pytest.raises(ValueError, match="not a valid thing name"):
        topics.room_robot_speech("a/b")


def test_an_utterance_round_trips_with_its_audio() -> None:
    audio = Audio(bytes(range(256)) * 10)
    sent = Utterance.new("placebot1", "assistant", audio, in_reply_to="q1")
    body = json.loads(sent.encode())
    assert {k: body[k] for k in ("thing", "speaker", "in_reply_to", "format")} == {
        "thing": "placebot1", "speaker": "assistant", "in_reply_to": "q1", "format": "wav",
    }  # fmt: skip
    assert base64.b64decode(body["audio"])[:4] == b"RIFF"
    assert Utterance.decode(sent.encode()) == sent


@pytest.mark.parametrize(
    ("payload", "reason"),
    [
        (b"not json", "not an utterance"),
        (b'{"id": "1", "thing": "p", "speaker": "robot"}', "not an utterance"),
        (b'{"id": "1", "thing": "p", "speaker": "cat", "audio": ""}', "speaker 'cat'"),
        (b'{"id": "1", "thing": "p", "speaker": "robot", "audio": "%%%"}', "not an utterance"),
        (b"x" * (MAX_MESSAGE_BYTES + 1), "over"),
    ],
)
def test_a_bad_room_message_is_a_voice_error(payload: bytes, reason: str) -> None:
    with pytest.raises(SpeechError, match=reason):
        Utterance.decode(payload)


def test_an_utterance_too_long_for_the_channel_is_refused() -> None:
    with pytest.raises(SpeechError, match="too long for the room channel"):
        Utterance.new("placebot1", "robot", Audio.silence(40.0)).encode()
