"""Text-to-speech: espeak-ng, flite and festival offline, Amazon Polly and gTTS optional.

Every synthesizer returns `Audio` at 16 kHz mono, the rate the recognizers and the room
channel use. espeak-ng (the default), flite, festival and sox run as subprocesses; boto3
and gTTS are imported only when their synthesizer is built, so the default path needs
neither.

A voice has one name, `ENGINE:VOICE`, wherever voices are listed (the hearing's
evaluations speak with many): `espeak-ng:en-us+f2`, `flite:slt` (also `rms`, `awb`,
`kal`), `festival:cmu_us_slt_arctic_hts`. flite's and festival's voices are diphone and
HMM voices built from recordings of people, so they sound far more like a person than
espeak-ng's formant synthesis, and a recognizer trained on people hears them better;
a hearing measured on espeak-ng alone says little about people.
"""

from __future__ import annotations

import shutil
import subprocess
import tempfile
from pathlib import Path
from typing import TYPE_CHECKING, Any, Protocol

from vahr.speech.audio import SAMPLE_RATE, Audio, convert_to_pcm16k
from vahr.speech.errors import SpeechError

if TYPE_CHECKING:
    from collections.abc import Callable

DEFAULT_VOICE = "en-us+f2"
DEFAULT_WORDS_PER_MINUTE = 150
ESPEAK_TIMEOUT_S = 10.0
# festival starts a Scheme interpreter and loads its voice for every sentence: about 2 s.
FESTIVAL_TIMEOUT_S = 30.0
MAX_TEXT_CHARS = 1_000
FLITE_VOICES = ("slt", "rms", "awb", "kal")
FESTIVAL_VOICES = ("cmu_us_slt_arctic_hts",)
# Voices spoken in the hearing's evaluations, engine by engine (see `voice_names`).
ESPEAK_VOICES = ("en-us+f2", "en-us+m3", "en-us+f4", "en+m1", "en-gb+f3")


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


class FliteSynthesizer:
    """flite (`-voice NAME -o FILE.wav`): CMU's small synthesizer, 16 kHz already."""

    def __init__(self, voice: str = "slt") -> None:
        executable = shutil.which("flite")
        if executable is None:
            raise SpeechError("flite is not installed (Debian: apt-get install flite)")
        if voice not in FLITE_VOICES:
            raise SpeechError(f"flite voice {voice!r}: use one of {', '.join(FLITE_VOICES)}")
        self.executable = executable
        self.voice = voice

    def synthesize(self, text: str) -> Audio:
        text = _check_text(text)
        with tempfile.TemporaryDirectory() as folder:
            out = Path(folder) / "speech.wav"
            # The text is read from a file: flite's -t would take a leading "-" as an option.
            source = Path(folder) / "text.txt"
            source.write_text(text, encoding="utf-8")
            command = [self.executable, "-voice", self.voice, "-f", str(source), "-o", str(out)]
            return _run_to_wav(command, out, "flite", ESPEAK_TIMEOUT_S, text=None)


class FestivalSynthesizer:
    """festival's `text2wave` with an installed voice (Debian: festvox-us-slt-hts for
    `cmu_us_slt_arctic_hts`), resampled from its 32 kHz (HTS) to 16 kHz by sox."""

    def __init__(self, voice: str = "cmu_us_slt_arctic_hts") -> None:
        executable = shutil.which("text2wave")
        if executable is None:
            raise SpeechError(
                "festival is not installed (Debian: apt-get install festival festvox-us-slt-hts)"
            )
        # A voice name goes into a Scheme expression: only a plain name may.
        if not voice.replace("_", "").isalnum():
            raise SpeechError(f"festival voice {voice!r} is not a voice name")
        self.executable = executable
        self.voice = voice

    def synthesize(self, text: str) -> Audio:
        text = _check_text(text)
        with tempfile.TemporaryDirectory() as folder:
            out = Path(folder) / "speech.wav"
            command = [
                self.executable, "-eval", f"(voice_{self.voice})", "-o", str(out),
            ]  # fmt: skip
            # The text goes in on stdin, read as text (not as Scheme).
            return _run_to_wav(command, out, "festival", FESTIVAL_TIMEOUT_S, text=text)


def _run_to_wav(
    command: list[str], out: Path, engine: str, timeout_s: float, *, text: str | None
) -> Audio:
    try:
        done = subprocess.run(
            command,
            input=text.encode() if text is not None else None,
            capture_output=True,
            timeout=timeout_s,
            check=False,
        )
    except subprocess.TimeoutExpired as err:
        raise SpeechError(f"{engine} did not finish within {timeout_s:g} s") from err
    message = done.stderr.decode(errors="replace").strip()
    # festival says "SIOD ERROR" and may still exit 0 when a voice is missing.
    if done.returncode != 0 or not out.is_file() or out.stat().st_size <= 44 or "ERROR" in message:
        reason = message.splitlines()[-1] if message else "no audio produced"
        raise SpeechError(f"{engine} could not speak: {reason}")
    return Audio.from_wav(out.read_bytes())


def voice_names() -> dict[str, tuple[str, ...]]:
    """Every offline voice by engine, as `make_synthesizer` names them."""
    return {
        "espeak-ng": tuple(f"espeak-ng:{v}" for v in ESPEAK_VOICES),
        "flite": tuple(f"flite:{v}" for v in FLITE_VOICES),
        "festival": tuple(f"festival:{v}" for v in FESTIVAL_VOICES),
    }


def engine_of(spec: str) -> str:
    """The engine of a voice name: `flite:slt` -> `flite`; `espeak` is `espeak-ng`."""
    kind = spec.partition(":")[0]
    return "espeak-ng" if kind in ("", "espeak") else kind


def make_synthesizer(spec: str) -> Synthesizer:
    """`espeak-ng[:VOICE]` (or `espeak[:VOICE]`, the default), `flite[:VOICE]`,
    `festival[:VOICE]`, `polly[:VOICE]` or `gtts[:LANG]`."""
    kind, _, option = spec.partition(":")
    if kind in ("", "espeak", "espeak-ng"):
        return EspeakSynthesizer(option or DEFAULT_VOICE)
    if kind == "flite":
        return FliteSynthesizer(option or "slt")
    if kind == "festival":
        return FestivalSynthesizer(option or FESTIVAL_VOICES[0])
    if kind == "polly":
        return PollySynthesizer(option or "Joanna")
    if kind == "gtts":
        return GttsSynthesizer(option or "en")
    raise SpeechError(
        f"unknown synthesizer {spec!r}: use espeak-ng[:VOICE], flite[:VOICE], "
        "festival[:VOICE], polly[:VOICE], gtts"
    )
