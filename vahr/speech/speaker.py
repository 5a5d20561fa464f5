"""Speak the assistant's replies aloud with espeak-ng (for `vahr console --speak`), in the
voice of the reply's language (`voice_for`: "en-us+f4", German "de+f4")."""

from __future__ import annotations

import shutil
import subprocess

from vahr.errors import VahrError

VOICE = "en-us+f4"
SPEAK_TIMEOUT_S = 30.0


def voice_for(locale: str) -> str:
    """The espeak-ng voice replies in `locale` are spoken with (its language.yaml's)."""
    from vahr.domain.locale import DEFAULT_LOCALE, load_language

    if locale == DEFAULT_LOCALE:
        return VOICE
    return load_language(locale).speech.espeak_voice + "+f4"


def speak(text: str, *, voice: str = VOICE) -> None:
    binary = shutil.which("espeak-ng")
    if binary is None:
        raise VahrError("espeak-ng is not installed; run: sudo apt-get install -y espeak-ng")
    try:
        subprocess.run(
            [binary, "-v", voice, "-s", "165", text],
            check=False,
            timeout=SPEAK_TIMEOUT_S,
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
        )
    except subprocess.TimeoutExpired:
        raise VahrError("espeak-ng did not finish speaking in time") from None
