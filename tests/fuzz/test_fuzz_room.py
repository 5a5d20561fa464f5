"""Fuzz: room messages (speech between a robot and the assistant over the broker).

Property: `Utterance.decode` returns an utterance or raises `SpeechError` in one line;
nothing else escapes, so the room channel can log and drop what is not speech.
"""

from __future__ import annotations

import base64

from hypothesis import given, settings
from hypothesis import strategies as st

from tests.fuzz.strategies import deep_arrays, encode, json_values, text
from tests.fuzz.tally import TALLY, budget
from vahr.speech.errors import SpeechError
from vahr.speech.room_channel import Utterance

WAV = base64.b64encode(
    b"RIFF$\x00\x00\x00WAVEfmt \x10\x00\x00\x00\x01\x00\x01\x00\x80>\x00\x00\x00}\x00\x00"
    b"\x02\x00\x10\x00data\x00\x00\x00\x00"
).decode()


@st.composite
def room_messages(draw: st.DrawFn) -> bytes:
    body = {
        "id": draw(st.one_of(text, st.integers())),
        "thing": draw(st.sampled_from(["placebot1", "placebot2", ""])),
        "speaker": draw(st.one_of(st.sampled_from(["robot", "assistant"]), text)),
        "in_reply_to": draw(st.one_of(st.none(), text)),
        "format": "wav",
        "audio": draw(st.one_of(st.just(WAV), text, st.binary(max_size=64).map(
            lambda b: base64.b64encode(b).decode()
        ))),
    }  # fmt: skip
    for key in draw(st.lists(st.sampled_from(sorted(body)), max_size=2)):
        if draw(st.booleans()):
            body.pop(key, None)
        else:
            body[key] = draw(json_values(4))
    return encode(body)


PAYLOADS = st.one_of(
    room_messages(),
    json_values().map(encode),
    st.binary(max_size=64),
    st.integers(900, 4000).map(deep_arrays),
)


@given(payload=PAYLOADS)
@settings(max_examples=budget(200))
def test_a_room_message_is_speech_or_refused_in_one_line(payload: bytes) -> None:
    try:
        Utterance.decode(payload)
    except SpeechError as err:
        assert str(err) and "\n" not in str(err)[:200]
        TALLY.rejected("room message (speech over MQTT)", "utterance")
        return
    TALLY.accepted("room message (speech over MQTT)")
