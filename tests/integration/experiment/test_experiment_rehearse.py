"""`vahr rehearse`: a whole simulated study on a stack of its own, beside the paper's Table II."""

from __future__ import annotations

import json
from typing import TYPE_CHECKING

import pytest

from vahr.cli import main
from vahr.experiment.eventlog import Kind, read_log

if TYPE_CHECKING:
    from pathlib import Path


def test_a_small_rehearsal_writes_the_csv_the_report_and_the_paper_beside_it(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "rehearsal"
    # When a study of two participants, one trial per method, is rehearsed (at twice the
    # default speed: the run waits on simulated time, and nothing here reads its figures)
    code = main(
        ["rehearse", "--participants", "2", "--trials", "1", "--speed-factor", "60",
         "--out", str(out)]
    )  # fmt: skip
    printed = capsys.readouterr()
    # Then it printed the paper's Table II beside the rehearsal's, labelled simulated
    assert code == 0, printed.err[-2000:]
    assert "SIMULATED participants, not people" in printed.out
    assert "| metric | paper VAHR | paper keyboard | paper p | rehearsal VAHR |" in printed.out
    assert "| Interaction time (IE) | 111 | 175 |" in printed.out
    # and every session ran, counterbalanced: P01 starts with VAHR, P02 with the keyboard
    started = [line for line in printed.err.splitlines() if "trial 1: tasks" in line]
    assert [line.split()[1:3] for line in started] == [
        ["P01", "vahr"],
        ["P01", "keyboard"],
        ["P02", "keyboard"],
        ["P02", "vahr"],
    ]
    assert all("tasks 3/3" in line for line in started), started
    logs = sorted((out / "logs").glob("*.sqlite"))
    assert len(logs) == 4
    assert all(read_log(p)[0].data["simulated"] is True for p in logs)
    assert all(read_log(p)[-1].kind == Kind.SESSION_ENDED for p in logs)
    # and report.json keeps the paper's contract and sets the paper beside it
    report = json.loads((out / "report.json").read_text())
    assert report["simulated"] is True and report["participants"] == 2
    assert [line["metric"] for line in report["paper_comparison"]] == [
        "interaction_time",
        "neglect_time",
        "rad",
        "fan_out",
        "puzzle_parts",
        "time_taken",
    ]
    assert all(isinstance(line["direction_agrees"], bool) for line in report["paper_comparison"])
    assert "Beside the paper's Table II (simulated)" in (out / "report.md").read_text()
    for name in ("objective.png", "objective.svg", "trial_change.png", "trial_change.svg"):
        assert (out / name).stat().st_size > 1000
    # When `vahr report` reads the CSV the rehearsal wrote
    assert main(["report", str(out / "results.csv"), "--out", str(tmp_path / "again")]) == 0
    again = json.loads((tmp_path / "again" / "report.json").read_text())
    # Then it finds the same means
    assert again["objective"]["rad"]["means"] == pytest.approx(
        report["objective"]["rad"]["means"], rel=1e-3
    )


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["--participants", "0"], "--participants and --trials must be 1 or more"),
        (["--speed-factor", "0"], "--speed-factor must be more than 0"),
        (
            ["--api", "http://127.0.0.1:1"],
            "--api and --broker go together (a running `vahr up`'s endpoints)",
        ),
    ],
)
def test_bad_flags_are_refused_in_one_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], argv: list[str], message: str
) -> None:
    code = main(["rehearse", "--out", str(tmp_path / "out"), *argv])
    err = capsys.readouterr().err.strip()
    assert code == 2 and err == f"vahr rehearse: error: {message}"
    assert not (tmp_path / "out").exists()
