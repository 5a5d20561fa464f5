"""The device voice, with sox standing in for the sound card's player and recorder (the
same stdin/stdout contract as aplay and arecord): no sound card exists on this machine."""

from __future__ import annotations

import asyncio
import time
from typing import TYPE_CHECKING

import pytest

from robot_agent.config import ListenSettings
from robot_agent.voice.devices import DeviceVoice
from vahr.speech.audio import Audio, concatenate
from vahr.speech.errors import SpeechError
from vahr.speech.tts import EspeakSynthesizer

if TYPE_CHECKING:
    from pathlib import Path

    from robot_agent.voice.hearing import Hearing

RAW_16K = ["-t", "raw", "-r", "16000", "-c", "1", "-b", "16", "-e", "signed-integer", "-"]


def recorder_of(wav: Path) -> list[str]:
    """A recorder that 'hears' a file: sox writes it as raw PCM on stdout, like arecord."""
    return ["sox", str(wav), *RAW_16K]


@pytest.fixture(scope="module")
def tts() -> EspeakSynthesizer:
    return EspeakSynthesizer("en-us+m3")


def test_listen_hears_the_answer_between_silences(
    tmp_path: Path, hearing: Hearing, tts: EspeakSynthesizer
) -> None:
    # Given a microphone that picks up a second of silence, the answer, then a long silence
    # and more talk (which must not be part of the answer)
    room = concatenate(
        Audio.silence(1.0),
        tts.synthesize("It is raining."),
        Audio.silence(1.5),
        tts.synthesize("Please deliver the package to the loading zone."),
    )
    wav = tmp_path / "room.wav"
    wav.write_bytes(room.to_wav())
    voice = DeviceVoice(tts, hearing, player=["true"], recorder=recorder_of(wav))
    # When the robot listens
    heard = asyncio.run(voice.listen(timeout_s=5.0))
    # Then it understood the answer only
    assert (heard.intent, heard.text) == ("rainy", "it is raining")


def test_listen_times_out_on_silence(
    tmp_path: Path, hearing: Hearing, tts: EspeakSynthesizer
) -> None:
    wav = tmp_path / "quiet.wav"
    wav.write_bytes(Audio.silence(10.0).to_wav())
    voice = DeviceVoice(tts, hearing, player=["true"], recorder=recorder_of(wav))
    started = time.monotonic()
    heard = asyncio.run(voice.listen(timeout_s=2.0))
    assert (heard.intent, heard.text, heard.confidence) == ("unknown", "", 0.0)
    assert time.monotonic() - started < 2.0  # audio time, not wall time, for a file


def test_listen_bounds_a_stalled_microphone_by_wall_time(
    hearing: Hearing, tts: EspeakSynthesizer
) -> None:
    # A recorder that never delivers a byte (a wedged device)
    voice = DeviceVoice(
        tts, hearing, player=["true"], recorder=["sleep", "30"],
        settings=ListenSettings(max_utterance_s=0.5),
    )  # fmt: skip
    started = time.monotonic()
    heard = asyncio.run(voice.listen(timeout_s=0.5))
    assert heard.intent == "unknown"
    assert time.monotonic() - started < 3.0


def test_say_plays_the_speech_on_the_player(
    tmp_path: Path, hearing: Hearing, tts: EspeakSynthesizer
) -> None:
    # Given a player that writes what it is sent to a file (as aplay would play it)
    played = tmp_path / "played.wav"
    voice = DeviceVoice(
        tts, hearing, player=["sox", "-t", "wav", "-", str(played)], recorder=["true"]
    )
    # When the robot speaks
    asyncio.run(voice.say("The weather is sunny."))
    # Then the played audio is that sentence
    heard = hearing.hear(Audio.from_wav(played.read_bytes()))
    assert heard.text == "the weather is sunny"


def test_a_missing_device_command_is_a_voice_error(
    hearing: Hearing, tts: EspeakSynthesizer
) -> None:
    voice = DeviceVoice(tts, hearing, player=["no-such-player"], recorder=["no-such-recorder"])
    with pytest.raises(SpeechError, match="audio player 'no-such-player' not found"):
        asyncio.run(voice.say("hello"))
    with pytest.raises(SpeechError, match="audio recorder 'no-such-recorder' not found"):
        asyncio.run(voice.listen(1.0))


def test_a_failing_recorder_says_why(hearing: Hearing, tts: EspeakSynthesizer) -> None:
    voice = DeviceVoice(
        tts,
        hearing,
        player=["true"],
        recorder=["sh", "-c", "echo 'no such device' >&2; exit 1"],
    )
    with pytest.raises(SpeechError, match="no such device"):
        asyncio.run(voice.listen(1.0))
