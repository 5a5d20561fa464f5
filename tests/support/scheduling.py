"""How `pytest -n 2 --dist loadgroup` shares the suite between its two workers.

Each test file is one unit of work and runs whole on one worker, so its module fixtures (a
stack, `vahr up`, a browser, a trained model) start once; every infra test is one unit,
since the CDK apps they share are synthesized once per session.

pytest-xdist names a test's group by appending `@group` to its node id, which pytest 9.2's
structured node ids no longer allow (pytest-dev/pytest-xdist#1386): the `xdist_group` marks
were ignored and every test was scheduled alone, on either worker. The group is therefore
read from the node id here, in the scheduler, instead.

Units are handed out in collection order, which `slow_files_first` sets: the files with a
test marked `slow` go first, so that no long file is left to start when the other worker
has run out of work.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from xdist.scheduler import LoadGroupScheduling

if TYPE_CHECKING:
    import pytest
    from xdist.remote import Producer

INFRA = "tests/infra/"


def group_of(nodeid: str) -> str:
    """The unit of work a test belongs to: its file, or `infra` for every infra test."""
    path = nodeid.split("::", 1)[0]
    return "infra" if path.startswith(INFRA) else path


class FileGroupScheduling(LoadGroupScheduling):
    """`--dist loadgroup` with a group per file (see the module docstring)."""

    def __init__(self, config: pytest.Config, log: Producer | None = None) -> None:
        super().__init__(config, log)
        # Keep the collection order (slow files first) rather than the largest file first.
        config.option.loadscopereorder = False

    def _split_scope(self, nodeid: str) -> str:
        named = super()._split_scope(nodeid)
        # An `@group` suffix, should xdist add one again, is honoured as it is.
        return named if named != nodeid else group_of(nodeid)


def slow_files_first(items: list[pytest.Item]) -> None:
    """Reorder `items` in place: whole files holding a `slow` test first, each file's own
    order and the order of the files otherwise kept."""
    slow = {group_of(item.nodeid) for item in items if item.get_closest_marker("slow")}
    items.sort(key=lambda item: group_of(item.nodeid) not in slow)
