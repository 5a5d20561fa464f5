"""How spoken phrases are compared: lower case, punctuation dropped, single spaces.

Grammars, recognized text and sample phrasings all pass through `normalize`, so a phrase
written "It's sunny." in a file is the phrase the recognizer returns as "it's sunny".
"""

from __future__ import annotations

import re

_NOT_WORD = re.compile(r"[^a-z0-9' ]+")


def normalize(text: str) -> str:
    """Lower case, punctuation removed, single spaces: how phrases are compared."""
    cleaned = _NOT_WORD.sub(" ", text.lower().replace("\u2019", "'"))
    return " ".join(word.strip("'") for word in cleaned.split() if word.strip("'"))
