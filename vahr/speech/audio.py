"""Speech audio as the voice path handles it: 16 kHz mono 16-bit PCM, plus WAV in and out.

Every recognizer here wants 16 kHz mono; WAV files from elsewhere (44.1 kHz stereo, 8-bit,
float) are converted once with sox, the one resampler the project depends on. Energy-based
speech detection lives here too, shared by the device listener and the recognizer.
"""

from __future__ import annotations

import io
import shutil
import subprocess
import wave
from dataclasses import dataclass

import numpy as np

from vahr.speech.errors import SpeechError

SAMPLE_RATE = 16_000
SAMPLE_WIDTH = 2  # bytes: signed 16-bit little-endian
FRAME_MS = 10
FRAME_SAMPLES = SAMPLE_RATE * FRAME_MS // 1000
# Full scale for 16-bit audio; levels below are in dB relative to it (dBFS).
_FULL_SCALE = 32768.0
SOX_TIMEOUT_S = 10.0


@dataclass(frozen=True)
class Audio:
    """Mono 16-bit PCM at `SAMPLE_RATE`, as little-endian bytes."""

    pcm: bytes

    @property
    def seconds(self) -> float:
        return len(self.pcm) / (SAMPLE_RATE * SAMPLE_WIDTH)

    def samples(self) -> np.ndarray:
        return np.frombuffer(self.pcm, dtype="<i2")

    @classmethod
    def from_samples(cls, samples: np.ndarray) -> Audio:
        clipped = np.clip(np.rint(samples), -32768, 32767).astype("<i2")
        return cls(clipped.tobytes())

    @classmethod
    def silence(cls, seconds: float) -> Audio:
        return cls(bytes(int(seconds * SAMPLE_RATE) * SAMPLE_WIDTH))

    def to_wav(self) -> bytes:
        """A standard RIFF WAV file of this audio."""
        buffer = io.BytesIO()
        with wave.open(buffer, "wb") as out:
            out.setnchannels(1)
            out.setsampwidth(SAMPLE_WIDTH)
            out.setframerate(SAMPLE_RATE)
            out.writeframes(self.pcm)
        return buffer.getvalue()

    @classmethod
    def from_wav(cls, data: bytes) -> Audio:
        """Read any WAV sox understands; 16 kHz mono 16-bit is read without converting."""
        try:
            with wave.open(io.BytesIO(data), "rb") as wav:
                if (wav.getnchannels(), wav.getsampwidth(), wav.getframerate()) == (
                    1,
                    SAMPLE_WIDTH,
                    SAMPLE_RATE,
                ):
                    return cls(wav.readframes(wav.getnframes()))
        except (wave.Error, EOFError, RuntimeError):
            # A float or extensible WAV, which the wave module cannot read: sox can. (It
            # raises RuntimeError for a chunk that claims more bytes than the file has:
            # sox then says in one line what is wrong with it.)
            pass
        return cls(convert_to_pcm16k(data, "wav"))


def convert_to_pcm16k(data: bytes, file_type: str) -> bytes:
    """Convert audio of `file_type` (wav, mp3...) to raw 16 kHz mono 16-bit PCM with sox."""
    sox = shutil.which("sox")
    if sox is None:
        raise SpeechError("sox is not installed (Debian: apt-get install sox)")
    try:
        # -R: repeatable dither, so the same input always gives the same samples (the
        # spoken evaluation set is rendered byte for byte alike on every run).
        done = subprocess.run(
            [sox, "-R", "-t", file_type, "-", "-t", "raw", "-r", str(SAMPLE_RATE), "-c", "1",
             "-b", "16", "-e", "signed-integer", "-L", "-"],
            input=data,
            capture_output=True,
            timeout=SOX_TIMEOUT_S,
            check=False,
        )  # fmt: skip
    except subprocess.TimeoutExpired as err:
        raise SpeechError(f"sox did not convert the audio within {SOX_TIMEOUT_S:g} s") from err
    if done.returncode != 0:
        reason = done.stderr.decode(errors="replace").strip().splitlines()
        raise SpeechError(f"not readable audio: {reason[-1] if reason else 'sox failed'}")
    return done.stdout


def frame_levels_dbfs(audio: Audio) -> np.ndarray:
    """The RMS level of each 10 ms frame in dBFS (silence is about -100)."""
    samples = audio.samples().astype(np.float64)
    count = len(samples) // FRAME_SAMPLES
    if count == 0:
        return np.zeros(0)
    frames = samples[: count * FRAME_SAMPLES].reshape(count, FRAME_SAMPLES)
    rms = np.sqrt(np.mean(frames**2, axis=1))
    return 20 * np.log10(np.maximum(rms, 1e-5 * _FULL_SCALE) / _FULL_SCALE)


@dataclass(frozen=True)
class SpeechDetector:
    """Finds speech by energy: frames louder than `threshold_dbfs` for at least
    `min_speech_ms` in total are speech; a gap of `min_pause_ms` splits utterances."""

    threshold_dbfs: float = -45.0
    min_speech_ms: int = 120
    min_pause_ms: int = 300

    def is_speech(self, levels: np.ndarray) -> np.ndarray:
        return levels > self.threshold_dbfs

    def has_speech(self, audio: Audio) -> bool:
        voiced = int(self.is_speech(frame_levels_dbfs(audio)).sum())
        return voiced * FRAME_MS >= self.min_speech_ms

    def segments(self, audio: Audio) -> list[tuple[int, int]]:
        """Sample ranges [start, end) of utterances separated by pauses of `min_pause_ms`."""
        voiced = self.is_speech(frame_levels_dbfs(audio))
        pause_frames = self.min_pause_ms // FRAME_MS
        spans: list[tuple[int, int]] = []
        start = last = None
        for index, loud in enumerate(voiced):
            if not loud:
                continue
            if start is None:
                start = index
            elif last is not None and index - last > pause_frames:
                spans.append((start, last + 1))
                start = index
            last = index
        if start is not None and last is not None:
            spans.append((start, last + 1))
        minimum = self.min_speech_ms // FRAME_MS
        return [(s * FRAME_SAMPLES, e * FRAME_SAMPLES) for s, e in spans if e - s >= minimum]


def add_white_noise(audio: Audio, snr_db: float, rng: np.random.Generator) -> Audio:
    """`audio` with Gaussian white noise at `snr_db` relative to the audio's mean power."""
    samples = audio.samples().astype(np.float64)
    power = float(np.mean(samples**2)) if len(samples) else 0.0
    noise = rng.normal(0.0, np.sqrt(power / 10 ** (snr_db / 10)), len(samples))
    return Audio.from_samples(samples + noise)


def concatenate(*parts: Audio) -> Audio:
    return Audio(b"".join(part.pcm for part in parts))
