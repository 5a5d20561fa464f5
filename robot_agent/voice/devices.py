"""The robot's own speaker and microphone: a `Voice` on a real sound device.

Speech is played by a player command that reads a WAV file on stdin (`aplay -q -`) and
heard through a recorder command that writes raw 16 kHz mono 16-bit PCM on stdout
(`arecord -q -t raw -f S16_LE -r 16000 -c 1`). Listening waits up to the timeout for speech
to start, keeps recording until a trailing silence (the answer is over) or a maximum
length, then stops the recorder and understands what it got. Any command with the same
contract works, which is also how this adapter is tested without a sound card.
"""

from __future__ import annotations

import asyncio
import select
import shutil
import subprocess
import time
from typing import TYPE_CHECKING

from robot_agent.config import ListenSettings
from robot_agent.voice.port import Heard
from vahr.speech.audio import (
    FRAME_MS,
    FRAME_SAMPLES,
    SAMPLE_RATE,
    SAMPLE_WIDTH,
    Audio,
    SpeechDetector,
    frame_levels_dbfs,
)
from vahr.speech.errors import SpeechError

if TYPE_CHECKING:
    from collections.abc import Sequence

    from robot_agent.voice.hearing import Hearing
    from vahr.speech.tts import Synthesizer

PLAY_GRACE_S = 5.0
STOP_TIMEOUT_S = 2.0
_FRAME_BYTES = FRAME_SAMPLES * SAMPLE_WIDTH


def default_player() -> list[str]:
    if shutil.which("aplay"):
        return ["aplay", "-q", "-"]
    raise SpeechError("no audio player: install alsa-utils (aplay) or set VAHR_PLAY_COMMAND")


def default_recorder() -> list[str]:
    if shutil.which("arecord"):
        return ["arecord", "-q", "-t", "raw", "-f", "S16_LE", "-r", str(SAMPLE_RATE), "-c", "1"]
    raise SpeechError("no audio recorder: install alsa-utils (arecord) or set VAHR_RECORD_COMMAND")


class DeviceVoice:
    """A `Voice` that plays and records through commands (aplay/arecord by default)."""

    def __init__(
        self,
        synthesizer: Synthesizer,
        hearing: Hearing,
        *,
        player: Sequence[str],
        recorder: Sequence[str],
        detector: SpeechDetector | None = None,
        settings: ListenSettings | None = None,
    ) -> None:
        self.synthesizer = synthesizer
        self.hearing = hearing
        self.player = list(player)
        self.recorder = list(recorder)
        self.detector = detector or SpeechDetector()
        self.settings = settings or ListenSettings()

    async def say(self, text: str) -> None:
        audio = await asyncio.to_thread(self.synthesizer.synthesize, text)
        await asyncio.to_thread(self.play, audio)

    async def listen(self, timeout_s: float) -> Heard:
        audio = await asyncio.to_thread(self.record, timeout_s)
        if audio is None:
            return Heard("", "unknown", 0.0)
        return await asyncio.to_thread(self.hearing.hear, audio)

    def play(self, audio: Audio) -> None:
        try:
            done = subprocess.run(
                self.player,
                input=audio.to_wav(),
                capture_output=True,
                timeout=audio.seconds + PLAY_GRACE_S,
                check=False,
            )
        except FileNotFoundError as err:
            raise SpeechError(f"audio player {self.player[0]!r} not found") from err
        except subprocess.TimeoutExpired as err:
            raise SpeechError(f"the audio player did not finish within {err.timeout:g} s") from err
        if done.returncode != 0:
            reason = done.stderr.decode(errors="replace").strip()
            raise SpeechError(f"the audio player failed: {reason or done.returncode}")

    def record(self, timeout_s: float) -> Audio | None:
        """One utterance from the recorder, or None if no speech started within `timeout_s`."""
        try:
            process = subprocess.Popen(
                self.recorder, stdout=subprocess.PIPE, stderr=subprocess.PIPE
            )
        except FileNotFoundError as err:
            raise SpeechError(f"audio recorder {self.recorder[0]!r} not found") from err
        try:
            return self._capture(process, timeout_s)
        finally:
            process.kill()
            process.wait(STOP_TIMEOUT_S)
            if process.stdout is not None:
                process.stdout.close()
            if process.stderr is not None:
                process.stderr.close()

    def _capture(self, process: subprocess.Popen[bytes], timeout_s: float) -> Audio | None:
        assert process.stdout is not None
        settings = self.settings
        frames: list[bytes] = []
        pre_roll = max(1, settings.pre_roll_ms // FRAME_MS)
        silence_needed = settings.trailing_silence_ms // FRAME_MS
        speech_needed = max(1, self.detector.min_speech_ms // FRAME_MS // 4)
        started_at: int | None = None  # frame index where speech began
        loud_run = quiet_run = 0
        pending = b""
        ended = False
        # Audio time bounds a fast source (a file); wall time bounds a stalled one.
        wall_deadline = time.monotonic() + timeout_s + settings.max_utterance_s
        while time.monotonic() < wall_deadline:
            ready, _, _ = select.select([process.stdout], [], [], 0.1)
            if not ready:
                continue
            chunk = process.stdout.read1(4096)  # type: ignore[attr-defined]
            if not chunk:
                ended = True
                break  # the recorder ended (a file ran out): use what there is
            pending += chunk
            while len(pending) >= _FRAME_BYTES:
                frame, pending = pending[:_FRAME_BYTES], pending[_FRAME_BYTES:]
                frames.append(frame)
                loud = bool(self.detector.is_speech(frame_levels_dbfs(Audio(frame)))[0])
                if started_at is None:
                    loud_run = loud_run + 1 if loud else 0
                    if loud_run >= speech_needed:
                        started_at = max(0, len(frames) - loud_run - pre_roll)
                    elif len(frames) * FRAME_MS >= timeout_s * 1000:
                        return None
                    continue
                quiet_run = 0 if loud else quiet_run + 1
                length_s = (len(frames) - started_at) * FRAME_MS / 1000
                if quiet_run >= silence_needed or length_s >= settings.max_utterance_s:
                    return Audio(b"".join(frames[started_at:]))
        if started_at is None:
            if not ended:
                return None  # a silent or stalled microphone until the deadline
            try:
                code = process.wait(STOP_TIMEOUT_S)
            except subprocess.TimeoutExpired:
                return None  # still running, only silent: the timeout passed
            if code != 0:
                stderr = process.stderr.read() if process.stderr is not None else b""
                reason = stderr.decode(errors="replace").strip()
                raise SpeechError(f"the audio recorder failed: {reason or code}")
            return None
        return Audio(b"".join(frames[started_at:]))
