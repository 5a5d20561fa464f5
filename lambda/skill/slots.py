"""Read a slot from an IntentRequest: what the person said and which id it resolved to.

Alexa's entity resolution is trusted first (ER_SUCCESS_MATCH carries the id), unless it
matched the words to several values: then the slot does not resolve and `choices` holds
the values the words fit, so the skill can ask which one was meant. When a
request carries no resolutions (a hand-built envelope, a test console), the spoken value is
looked up in the fleet's names, so the same words work either way.
"""

from __future__ import annotations

from functools import cache
from typing import TYPE_CHECKING

import msgspec

from vahr.domain.text import normalize, number_in_words

if TYPE_CHECKING:
    from collections.abc import Callable, Collection

    from ask_sdk_model import Intent, Slot

MATCH = "ER_SUCCESS_MATCH"


class SlotReading(msgspec.Struct, frozen=True):
    """One slot as heard: `heard` is None when missing, `id` is None when it did not resolve."""

    name: str
    heard: str | None
    id: str | None
    # The known values the words fit about equally (two or more), when they fit several.
    choices: tuple[str, ...] = ()

    @property
    def missing(self) -> bool:
        return self.heard is None

    @property
    def unresolved(self) -> bool:
        return self.heard is not None and self.id is None


def read_slot(
    intent: Intent,
    name: str,
    known_ids: Collection[str],
    lookup: Callable[[str], str | None],
) -> SlotReading:
    """Read slot `name`; ids outside `known_ids` count as unresolved."""
    slot = (intent.slots or {}).get(name)
    heard = (slot.value or "").strip() if slot is not None else ""
    if slot is None or not heard:
        return SlotReading(name, None, None)
    matched = resolved_ids(slot)
    if matched is None:
        return SlotReading(name, heard, lookup(heard))
    if len(matched) > 1:
        # The words fit several values ("robot" for either robot): taking the first would
        # act on a guess, so the slot counts as unresolved.
        known = tuple(value for value in matched if value in known_ids)
        return SlotReading(name, heard, None, known if len(known) > 1 else ())
    if matched and matched[0] in known_ids:
        return SlotReading(name, heard, matched[0])
    # Resolutions were present and none matched (ER_SUCCESS_NO_MATCH), or not a known id.
    return SlotReading(name, heard, None)


def resolved_ids(slot: Slot) -> list[str] | None:
    """The ids the first matching authority (ER_SUCCESS_MATCH) resolved the words to, each
    once, in Alexa's order; [] when resolutions came and none matched; None when the slot
    came without resolutions. Empty entries (a value, a wrapper or an authority that is
    null) are passed over: a request is outside input."""
    resolutions = slot.resolutions.resolutions_per_authority if slot.resolutions else None
    if not resolutions:
        return None
    for authority in resolutions:
        if authority is None:
            continue
        code = authority.status.code.value if authority.status and authority.status.code else None
        ids = [
            wrapper.value.id
            for wrapper in authority.values or []
            if wrapper is not None and wrapper.value is not None and wrapper.value.id
        ]
        if code == MATCH and ids:
            return list(dict.fromkeys(ids))
    return []


def spoken_number(heard: str | None) -> int | None:
    """A count as said ("2", "two", "twelve"), or None when it is no number to 99."""
    words = normalize(heard or "")
    if words.isdigit():
        return int(words)
    return _spoken_numbers().get(words)


@cache
def _spoken_numbers() -> dict[str | None, int]:
    """Numbers a person may say for a count, word -> value ("twelve" -> 12); built on first
    use, as the number words are read from the locale's data."""
    return {number_in_words(n): n for n in range(1, 100)}
