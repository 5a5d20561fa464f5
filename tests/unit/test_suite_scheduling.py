"""The suite's two workers each take whole files (tests/support/scheduling.py)."""

from __future__ import annotations

from types import SimpleNamespace
from typing import Any

import pytest

from tests.support.scheduling import FileGroupScheduling, group_of, longest_files_first


def _scheduler() -> FileGroupScheduling:
    # What `pytest -n 2 --dist loadgroup` gives the scheduler, and no more.
    config: Any = SimpleNamespace(
        option=SimpleNamespace(loadscopereorder=True),
        getvalue={"tx": ["popen", "popen"]}.get,
    )
    return FileGroupScheduling(config)


def test_a_files_tests_share_one_group_and_the_infra_tests_another() -> None:
    assert group_of("tests/unit/test_a.py::test_one[x-1]") == "tests/unit/test_a.py"
    assert group_of("tests/unit/test_a.py::TestB::test_two") == "tests/unit/test_a.py"
    assert group_of("tests/infra/test_x.py::test_one") == "infra"
    assert group_of("tests/infra/sub/test_y.py::test_two") == "infra"


def test_the_scheduler_groups_by_file_and_honours_an_xdist_group_suffix() -> None:
    scheduler = _scheduler()
    assert scheduler._split_scope("tests/unit/test_a.py::test_one[a@b]") == "tests/unit/test_a.py"
    assert scheduler._split_scope("tests/infra/test_x.py::test_one") == "infra"
    assert scheduler._split_scope("tests/unit/test_a.py::test_one@named") == "named"
    # The collection order (longest files first) is the order work is handed out in.
    assert scheduler.config.option.loadscopereorder is False


def test_files_that_declare_a_long_timeout_then_slow_files_come_first_whole() -> None:
    def item(nodeid: str, *marks: pytest.MarkDecorator) -> Any:
        found = {mark.name: mark.mark for mark in marks}
        return SimpleNamespace(nodeid=nodeid, get_closest_marker=found.get)

    items = [
        item("tests/unit/test_a.py::one"),
        item("tests/unit/test_b.py::one"),
        item("tests/unit/test_b.py::two", pytest.mark.slow),
        item("tests/infra/test_c.py::one"),
        item("tests/infra/test_d.py::one", pytest.mark.timeout(240)),
        item("tests/unit/test_e.py::one", pytest.mark.slow, pytest.mark.timeout(420)),
        item("tests/unit/test_f.py::one"),
    ]
    longest_files_first(items)
    assert [i.nodeid for i in items] == [
        "tests/unit/test_e.py::one",
        "tests/infra/test_c.py::one",
        "tests/infra/test_d.py::one",
        "tests/unit/test_b.py::one",
        "tests/unit/test_b.py::two",
        "tests/unit/test_a.py::one",
        "tests/unit/test_f.py::one",
    ]
