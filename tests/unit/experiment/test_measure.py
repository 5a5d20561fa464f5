"""IE, NT and time taken measured from hand-written logs, and the results row they make."""

from __future__ import annotations

from typing import TYPE_CHECKING

import pytest

from tests.unit.experiment.conftest import plan
from vahr.experiment.eventlog import Kind
from vahr.experiment.measure import measure_session
from vahr.experiment.results import row_from_log

if TYPE_CHECKING:
    from pathlib import Path

    from tests.unit.experiment.conftest import SessionScript


def test_interaction_effort_is_the_union_of_interactions_inside_tasks(
    script: SessionScript,
) -> None:
    # Given task I of 100 s with two utterances of 10 s, one overlapping a click of 6 s
    script.start_session(plan())
    script.start("I", 0)
    script.interact(5, 15)
    script.interact(12, 18)  # overlaps the first: 5..18 counts 13 s
    script.interact(40, 50)
    script.end(100)
    # and an utterance between tasks, which is not part of any task
    script.interact(110, 120)
    # and task II of 50 s where an utterance started before the task began
    script.start("II", 130)
    script.interact(125, 135)  # clipped to 130..135
    script.end(180)
    times = measure_session(script.log.entries())
    assert times.tasks["I"].interaction_s == pytest.approx(23)
    assert times.tasks["I"].neglect_s == pytest.approx(77)
    assert times.tasks["II"].interaction_s == pytest.approx(5)
    assert times.time_taken_s == pytest.approx(150)
    assert times.interaction_s + times.neglect_s == pytest.approx(times.time_taken_s)


def test_an_utterance_cut_by_a_crash_is_not_counted(script: SessionScript) -> None:
    script.start_session(plan())
    script.start("I", 0)
    script.log.append(Kind.INTERACTION_STARTED, {"id": "lost", "channel": "voice"}, task="I")
    script.end(30)
    times = measure_session(script.log.entries())
    assert times.unclosed_interactions == 1
    assert times.tasks["I"].interaction_s == 0


def test_a_session_log_becomes_a_results_row(script: SessionScript) -> None:
    script.start_session(plan(), participant="P09", trial=2)
    script.start("I", 0)
    script.interact(0, 20)
    script.puzzle(30)
    script.puzzle(40, count=2)
    script.end(80)
    script.log.append(
        Kind.TLX,
        {
            "levels": dict(
                mental=11,
                physical=1,
                temporal=21,
                performance=5,
                effort=6,
                frustration=7,
                confidence=18,
                trust=19,
            )
        },
    )
    row = row_from_log(script.log.entries())
    assert (row.participant, row.method, row.trial) == ("P09", "vahr", 2)
    assert (row.interaction_time_s, row.neglect_time_s, row.task_time_s) == (20, 60, 80)
    assert row.puzzle_parts == 3
    assert row.rad == 0.25
    assert row.fan_out == 320
    assert row.tlx is not None and row.tlx.percents()["mental"] == 50


def test_a_faster_than_real_time_rehearsal_is_measured_in_experiment_seconds(
    script: SessionScript,
) -> None:
    # Given a rehearsal logged at 20 times real time
    script.log.append(
        Kind.SESSION_STARTED,
        {"participant": "SIM", "method": "keyboard", "trial": 1, "speed_factor": 20.0},
    )
    script.start("I", 0)
    script.interact(1, 2)
    script.end(5)
    # Then one wall second of interaction is 20 experiment seconds
    times = measure_session(script.log.entries())
    assert (times.interaction_s, times.time_taken_s) == (20, 100)


def test_only_finished_sessions_become_rows(tmp_path: Path) -> None:
    from tests.unit.experiment.conftest import SessionScript as Story
    from vahr.experiment.eventlog import EventLog
    from vahr.experiment.results import rows_from_logs

    for name, finished in (("P01-vahr-trial1", True), ("P02-vahr-trial1", False)):
        with EventLog.open(tmp_path / f"{name}.sqlite") as log:
            story = Story(log)
            story.start_session(plan(), participant=name[:3])
            story.start("I", 0)
            story.interact(0, 10)
            story.end(40)
            if finished:
                log.append(Kind.SESSION_ENDED, {})
    rows, skipped = rows_from_logs(tmp_path)
    assert [row.participant for row in rows] == ["P01"]
    assert skipped == [
        "P02-vahr-trial1.sqlite: the session is not finished; resume it to include it"
    ]
