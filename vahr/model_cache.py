"""Where trained and built models are kept between runs, and how a file is put there.

Every model (the intent classifier, the role taggers, the language models, the station's
sentences) is kept under a hash of what it is made from, so a file is either the right one
or not read at all. A file appears whole or not at all: several processes (the robots of
`vahr up` on a first start) may write the same one at once.
"""

from __future__ import annotations

import contextlib
import hashlib
import importlib
import os
from functools import cache
from pathlib import Path

import msgspec


def default_cache_dir() -> Path:
    """$XDG_CACHE_HOME/vahr (or ~/.cache/vahr): trained models, keyed by their data."""
    base = os.environ.get("XDG_CACHE_HOME") or str(Path.home() / ".cache")
    return Path(base) / "vahr"


@cache
def code_digest(*modules: str) -> str:
    """A hash of the source of the modules named: what the code that makes a model adds to
    its key, so that a change to how it is made makes it anew."""
    code = hashlib.sha256()
    for name in modules:
        code.update(Path(str(importlib.import_module(name).__file__)).read_bytes())
    return code.hexdigest()


def content_key(made_from: object) -> str:
    """The cache key of what a model is made from: a sha256 (hex) of it written as JSON,
    mappings' keys sorted. msgspec writes it: the standard library's json took a third of a
    second for a fleet's sentences, at every start."""
    return hashlib.sha256(msgspec.json.encode(made_from, order="sorted")).hexdigest()


def write_atomically(file: Path, data: bytes) -> bool:
    """Write `data` to `file` through a file of this process's own, renamed into place;
    False (and nothing left behind) when the cache cannot be written: it is skipped."""
    partial = file.with_suffix(f".{os.getpid()}.tmp")
    try:
        file.parent.mkdir(parents=True, exist_ok=True)
        partial.write_bytes(data)
        partial.replace(file)
    except OSError:
        with contextlib.suppress(OSError):  # the folder itself may be what failed
            partial.unlink(missing_ok=True)
        return False
    return True
