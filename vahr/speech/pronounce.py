"""Pronunciations for words the recognizer's dictionary lacks (robot names such as
"placebot"), in the dictionary's phone set (CMU ARPAbet, no stress marks).

Two guesses, both kept as alternatives, since people and synthesizers say made-up words
differently:

- a compound of dictionary words, each said as the dictionary says it ("placebot" =
  "place" + "bot": P L EY S B AA T), as a person reading the name would;
- espeak-ng's own letter-to-sound rules (`espeak-ng -x`), its phonemes mapped to ARPAbet
  ("placebot": P L AH S EH B AA T), as espeak-ng itself would say it.
"""

from __future__ import annotations

import re
import shutil
import subprocess
from typing import TYPE_CHECKING

from vahr.speech.errors import SpeechError

if TYPE_CHECKING:
    from collections.abc import Callable

ESPEAK_TIMEOUT_S = 10.0
# espeak-ng's en-us phoneme mnemonics (`-x`) and the nearest ARPAbet phones; longest first
# when reading. Stress and syllable marks carry no phone.
_ESPEAK_TO_ARPABET = {
    "aI@": "AY ER", "aU@": "AW ER", "i@3": "IH R", "A@": "AA R", "e@": "EH R",
    "i@": "IH R", "U@": "UH R", "O@": "AO R", "o@": "AO R", "3:": "ER", "@L": "AH L",
    "@2": "AH", "@5": "AH", "a#": "AH", "A:": "AA", "aa": "AE", "aI": "AY", "aU": "AW",
    "eI": "EY", "i:": "IY", "I#": "IH", "I2": "IH", "O:": "AO", "oU": "OW", "OI": "OY",
    "u:": "UW", "t#": "T", "tS": "CH", "dZ": "JH", "n-": "N", "l-": "L",
    "@": "AH", "3": "ER", "a": "AE", "A": "AA", "E": "EH", "e": "EH", "i": "IY", "I": "IH",
    "0": "AA", "O": "AO", "u": "UW", "U": "UH", "V": "AH",
    "p": "P", "b": "B", "t": "T", "d": "D", "k": "K", "g": "G", "f": "F", "v": "V",
    "T": "TH", "D": "DH", "s": "S", "z": "Z", "S": "SH", "Z": "ZH", "h": "HH", "m": "M",
    "n": "N", "N": "NG", "l": "L", "r": "R", "w": "W", "j": "Y", "x": "K", "?": "T",
}  # fmt: skip
_SYMBOLS = sorted(_ESPEAK_TO_ARPABET, key=len, reverse=True)
_MARKS = re.compile(r"[',%=_|!]")


def espeak_phones(word: str, voice: str = "en-us") -> str:
    """How espeak-ng says `word`, in ARPAbet (raises SpeechError without espeak-ng)."""
    executable = shutil.which("espeak-ng")
    if executable is None:
        raise SpeechError("espeak-ng is not installed (Debian: apt-get install espeak-ng)")
    try:
        done = subprocess.run(
            [executable, "-v", voice, "-q", "-x", "--", word],
            capture_output=True,
            text=True,
            timeout=ESPEAK_TIMEOUT_S,
            check=False,
        )
    except subprocess.TimeoutExpired as err:
        raise SpeechError(f"espeak-ng did not answer within {ESPEAK_TIMEOUT_S:g} s") from err
    return arpabet(done.stdout)


def arpabet(mnemonics: str) -> str:
    """espeak-ng's phoneme mnemonics (`-x` output) as ARPAbet phones."""
    text = _MARKS.sub("", mnemonics.strip())
    phones: list[str] = []
    position = 0
    while position < len(text):
        if text[position].isspace():
            position += 1
            continue
        for symbol in _SYMBOLS:
            if text.startswith(symbol, position):
                phones.append(_ESPEAK_TO_ARPABET[symbol])
                position += len(symbol)
                break
        else:
            position += 1  # a mark this table does not know carries no phone
    return " ".join(phones)


def compound_phones(word: str, lookup: Callable[[str], str | None]) -> str | None:
    """`word` as two dictionary words said one after the other, if it splits so."""
    for cut in range(2, len(word) - 1):
        head, tail = lookup(word[:cut]), lookup(word[cut:])
        if head and tail:
            return f"{head} {tail}"
    return None


def guesses(word: str, lookup: Callable[[str], str | None]) -> list[str]:
    """Every pronunciation guessed for `word` (compound first), without repeats."""
    found = [compound_phones(word, lookup)]
    try:
        found.append(espeak_phones(word))
    except SpeechError:
        pass  # without espeak-ng, the compound reading alone
    return list(dict.fromkeys(p for p in found if p))
