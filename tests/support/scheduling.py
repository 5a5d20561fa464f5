"""How `pytest -n 3 --dist loadgroup` shares the suite between its workers.

Each test file is one unit of work and runs whole on one worker, so its module fixtures (a
stack, `vahr up`, a browser, a trained model) start once; every infra test is one unit,
since the CDK apps they share are synthesized once per session.

pytest-xdist names a test's group by appending `@group` to its node id, which pytest 9.2's
structured node ids no longer allow (pytest-dev/pytest-xdist#1386): the `xdist_group` marks
were ignored and every test was scheduled alone, on either worker. The group is therefore
read from the node id here, in the scheduler, instead.

Units are handed out in collection order, which `longest_files_first` sets: the files whose
tests declare a longer timeout of their own (the hearing acceptance, the installed package)
go first, then the files with a test marked `slow`, so that no long file is left to start
when the other workers have run out of work.
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
        # Keep the collection order (longest files first) rather than the largest first.
        config.option.loadscopereorder = False

    def _split_scope(self, nodeid: str) -> str:
        named = super()._split_scope(nodeid)
        # An `@group` suffix, should xdist add one again, is honoured as it is.
        return named if named != nodeid else group_of(nodeid)


def longest_files_first(items: list[pytest.Item]) -> None:
    """Reorder `items` in place, whole files at a time: the longest timeout a file's tests
    declare first, then files holding a `slow` test; each file's own order, and the order
    of files that tie, kept."""
    timeout: dict[str, float] = {}
    slow: set[str] = set()
    for item in items:
        group = group_of(item.nodeid)
        marker = item.get_closest_marker("timeout")
        if marker is not None and marker.args:
            timeout[group] = max(timeout.get(group, 0.0), float(marker.args[0]))
        if item.get_closest_marker("slow") is not None:
            slow.add(group)

    def order(item: pytest.Item) -> tuple[float, bool]:
        group = group_of(item.nodeid)
        return -timeout.get(group, 0.0), group not in slow

    items.sort(key=order)
