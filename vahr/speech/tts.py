"""Text-to-speech: espeak-ng offline (the default), Amazon Polly and gTTS optional.

Every synthesizer returns `Audio` at 16 kHz mono, the rate the recognizers and the room
channel use. espeak-ng and sox run as subprocesses; boto3 and gTTS are imported only
when their synthesizer is built, so the default path needs neither.
"""

from __future__ import annotations

import shutil
import subprocess
from typing import TYPE_CHECKING, Any, Protocol

from vahr.speech.audio import SAMPLE_RATE, Audio, convert_to_pcm16k
from vahr.speech.errors import SpeechError

if TYPE_CHECKING:
    from collections.abc import Callable

DEFAULT_VOICE = "en-us+f2"
DEFAULT_WORDS_PER_MINUTE = 150
ESPEAK_TIMEOUT_S = 10.0
MAX_TEXT_CHARS = 1_000


class Synthesizer(Protocol):
    def synthesize(self, text: str) -> Audio:
        """Render `text` as speech; raises SpeechError when it cannot."""
        ...


def _check_text(text: str) -> str:
    text = text.strip()
    if not text:
        raise SpeechError("nothing to say: the text is empty")
    if len(text) > MAX_TEXT_CHARS:
        raise SpeechError(f"the text is {len(text)} characters long; at most {MAX_TEXT_CHARS}")
    return text


class EspeakSynthesizer:
    """espeak-ng (`-v VOICE -s WPM --stdout`), resampled from 22,050 Hz to 16 kHz by sox."""

    def __init__(
        self, voice: str = DEFAULT_VOICE, words_per_minute: int = DEFAULT_WORDS_PER_MINUTE
    ) -> None:
        executable = shutil.which("espeak-ng")
        if executable is None:
            raise SpeechError("espeak-ng is not installed (Debian: apt-get install espeak-ng)")
        if not 80 <= words_per_minute <= 450:
            raise SpeechError(f"speed {words_per_minute} wpm: espeak-ng speaks 80 to 450")
        self.executable = executable
        self.voice = voice
        self.words_per_minute = words_per_minute

    def synthesize(self, text: str) -> Audio:
        text = _check_text(text)
        command = [self.executable, "-v", self.voice, "-s", str(self.words_per_minute)]
        try:
            # `--` so a text starting with "-" is spoken, not read as an option.
            done = subprocess.run(
                [*command, "--stdout", "--", text],
                capture_output=True,
                timeout=ESPEAK_TIMEOUT_S,
                check=False,
            )
        except subprocess.TimeoutExpired as err:
            raise SpeechError(f"espeak-ng did not finish within {ESPEAK_TIMEOUT_S:g} s") from err
        message = done.stderr.decode(errors="replace").strip()
        # espeak-ng exits 0 for an unknown voice; it only says so on stderr.
        if done.returncode != 0 or not done.stdout or "voice" in message.lower():
            raise SpeechError(f"espeak-ng voice {self.voice!r}: {message or 'no audio produced'}")
        return Audio(convert_to_pcm16k(done.stdout, "wav"))


class PollySynthesizer:
    """Amazon Polly `SynthesizeSpeech`, PCM at 16 kHz (no conversion needed)."""

    def __init__(self, voice: str = "Joanna", *, client: Any = None, engine: str = "standard"):
        if client is None:
            import boto3

            client = boto3.client("polly")
        self.client = client
        self.voice = voice
        self.engine = engine

    def synthesize(self, text: str) -> Audio:
        from botocore.exceptions import BotoCoreError, ClientError

        text = _check_text(text)
        try:
            response = self.client.synthesize_speech(
                Text=text,
                VoiceId=self.voice,
                OutputFormat="pcm",
                SampleRate=str(SAMPLE_RATE),
                Engine=self.engine,
            )
            pcm = response["AudioStream"].read()
        except (BotoCoreError, ClientError) as err:
            raise SpeechError(f"Amazon Polly could not speak: {err}") from err
        return Audio(pcm)


class GttsSynthesizer:
    """Google Translate's TTS through gTTS (needs the network and `pip install gTTS`)."""

    def __init__(self, language: str = "en", tld: str = "com") -> None:
        try:
            from gtts import gTTS
        except ImportError as err:
            raise SpeechError("the gtts voice needs `pip install gTTS`") from err
        self._make: Callable[..., Any] = gTTS
        self.language = language
        self.tld = tld

    def synthesize(self, text: str) -> Audio:
        import io

        text = _check_text(text)
        buffer = io.BytesIO()
        try:
            self._make(text=text, lang=self.language, tld=self.tld).write_to_fp(buffer)
        except Exception as err:  # gTTS raises its own and requests' errors
            raise SpeechError(f"gTTS could not speak: {err}") from err
        # sox reads MP3 only with libsox-fmt-mp3 installed; the error says so if not.
        return Audio(convert_to_pcm16k(buffer.getvalue(), "mp3"))


def make_synthesizer(spec: str) -> Synthesizer:
    """`espeak[:VOICE]` (default), `polly[:VOICE]` or `gtts[:LANG]`."""
    kind, _, option = spec.partition(":")
    if kind in ("", "espeak", "espeak-ng"):
        return EspeakSynthesizer(option or DEFAULT_VOICE)
    if kind == "polly":
        return PollySynthesizer(option or "Joanna")
    if kind == "gtts":
        return GttsSynthesizer(option or "en")
    raise SpeechError(f"unknown synthesizer {spec!r}: use espeak[:VOICE], polly[:VOICE], gtts")
