"""A robot's changes as the pages get them: what differs between two reported states, and
two changes the page has not taken yet folded into one.

The feed sends each page only what changed of a robot (`RobotChange`), and a page that has
not yet taken a robot's change gets the next one merged into it: however often a robot
reports between two of the page's frames, the page reads it once, with its latest values.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import msgspec

if TYPE_CHECKING:
    from vahr.station.page_messages import RobotChange

Json = dict[str, Any]
_MISSING = object()


def reported_change(before: Json | None, after: Json) -> tuple[Json, list[str]]:
    """The top-level fields of `after` that differ from `before` (with their new values),
    and the fields of `before` that `after` lacks."""
    if before is None:
        return dict(after), []
    changed = {key: value for key, value in after.items() if before.get(key, _MISSING) != value}
    removed = [key for key in before if key not in after]
    return changed, removed


def merge(earlier: RobotChange, later: RobotChange) -> None:
    """Fold `later` into `earlier` (the one a page has not taken yet), in place: the page
    ends in the same state as if it had applied both in turn. `earlier` must be a page's
    own copy (`own`)."""
    if not isinstance(later.reported, msgspec.UnsetType):
        if isinstance(earlier.reported, msgspec.UnsetType):
            earlier.reported = dict(later.reported)
        else:
            earlier.reported.update(later.reported)
        if not isinstance(earlier.removed, msgspec.UnsetType):
            earlier.removed = [key for key in earlier.removed if key not in later.reported]
    if not isinstance(later.removed, msgspec.UnsetType):
        if not isinstance(earlier.reported, msgspec.UnsetType):
            for key in later.removed:
                earlier.reported.pop(key, None)
        gone = [] if isinstance(earlier.removed, msgspec.UnsetType) else earlier.removed
        earlier.removed = gone + [key for key in later.removed if key not in gone]
    if isinstance(earlier.removed, list) and not earlier.removed:
        earlier.removed = msgspec.UNSET
    for name in ("version", "online", "last_seen", "progress", "last_event"):
        value = getattr(later, name)
        if not isinstance(value, msgspec.UnsetType):
            setattr(earlier, name, value)


def own(change: RobotChange) -> RobotChange:
    """A copy of `change` that `merge` may change (its reported fields copied too)."""
    copy = msgspec.structs.replace(change)
    if not isinstance(change.reported, msgspec.UnsetType):
        copy.reported = dict(change.reported)
    if not isinstance(change.removed, msgspec.UnsetType):
        copy.removed = list(change.removed)
    return copy
