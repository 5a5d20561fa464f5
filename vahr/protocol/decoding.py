"""JSON decoders built when first used, not at import.

Building a msgspec decoder resolves every annotation of its type, and with postponed
annotations Python compiles each one: about a hundred for the wire contract's messages,
most of the contract's import time. Every Lambda and robot imports the contract, and each
decodes only some of its messages, so each pays only for those.
"""

from __future__ import annotations

from typing import Any, Generic, TypeVar

import msgspec

T = TypeVar("T")


class LazyDecoder(Generic[T]):
    """`msgspec.json.Decoder(kind)`, built on the first `decode`."""

    def __init__(self, kind: Any) -> None:
        self._kind = kind
        self._decoder: msgspec.json.Decoder[T] | None = None

    def decode(self, data: bytes | bytearray | memoryview | str) -> T:
        decoder = self._decoder
        if decoder is None:
            decoder = self._decoder = msgspec.json.Decoder(self._kind)
        return decoder.decode(data)
