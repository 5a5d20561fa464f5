"""Audio handling: WAV in and out, conversion, levels, speech segments and noise."""

from __future__ import annotations

import io
import wave

import numpy as np
import pytest

from vahr.speech.audio import (
    SAMPLE_RATE,
    Audio,
    SpeechDetector,
    add_white_noise,
    concatenate,
)
from vahr.speech.errors import SpeechError


def tone(seconds: float, amplitude: float = 8000.0, hz: float = 440.0) -> Audio:
    t = np.arange(int(seconds * SAMPLE_RATE)) / SAMPLE_RATE
    return Audio.from_samples(amplitude * np.sin(2 * np.pi * hz * t))


def test_wav_round_trip_keeps_every_sample() -> None:
    audio = tone(0.25)
    assert Audio.from_wav(audio.to_wav()) == audio


def test_a_44k_stereo_wav_is_converted_to_16k_mono() -> None:
    # Given a CD-quality stereo WAV of one second
    buffer = io.BytesIO()
    with wave.open(buffer, "wb") as out:
        out.setnchannels(2)
        out.setsampwidth(2)
        out.setframerate(44_100)
        out.writeframes(np.zeros(2 * 44_100, dtype="<i2").tobytes())
    # When it is read
    audio = Audio.from_wav(buffer.getvalue())
    # Then it is one second at 16 kHz mono
    assert audio.seconds == pytest.approx(1.0, abs=0.01)


def test_not_audio_is_a_voice_error() -> None:
    with pytest.raises(SpeechError, match="not readable audio"):
        Audio.from_wav(b"this is not a wav file")


def test_silence_has_no_speech_and_a_tone_does() -> None:
    detector = SpeechDetector()
    assert not detector.has_speech(Audio.silence(1.0))
    assert detector.has_speech(tone(0.5))


def test_a_long_pause_splits_two_utterances() -> None:
    audio = concatenate(tone(0.4), Audio.silence(0.6), tone(0.3), Audio.silence(0.2))
    spans = SpeechDetector().segments(audio)
    assert [(round(s / SAMPLE_RATE, 2), round(e / SAMPLE_RATE, 2)) for s, e in spans] == [
        (0.0, 0.4),
        (1.0, 1.3),
    ]


def test_a_short_click_is_not_speech() -> None:
    audio = concatenate(Audio.silence(0.5), tone(0.05), Audio.silence(0.5))
    assert SpeechDetector().segments(audio) == []


def test_white_noise_is_added_at_the_requested_snr() -> None:
    clean = tone(1.0)
    noisy = add_white_noise(clean, 20.0, np.random.default_rng(1))
    signal = clean.samples().astype(float)
    noise = noisy.samples().astype(float) - signal
    snr = 10 * np.log10(np.mean(signal**2) / np.mean(noise**2))
    assert snr == pytest.approx(20.0, abs=0.3)
