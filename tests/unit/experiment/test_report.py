"""The report: means per method, one-way ANOVA as scipy computes it, Markdown, JSON, figures."""

from __future__ import annotations

import csv
import json
import random
from typing import TYPE_CHECKING

import pytest

from vahr.errors import VahrError
from vahr.experiment.report import build_report, write_report
from vahr.experiment.results import COLUMNS, read_csv
from vahr.experiment.tlx import ITEMS

if TYPE_CHECKING:
    from pathlib import Path

PNG_MAGIC = b"\x89PNG\r\n\x1a\n"


def generated_csv(path: Path, participants: int = 8, trials: int = 3, seed: int = 4) -> Path:
    """A data set shaped like the paper's: voice needs less interaction, more neglect."""
    rng = random.Random(seed)
    with path.open("w", newline="") as stream:
        writer = csv.DictWriter(stream, fieldnames=COLUMNS)
        writer.writeheader()
        for p in range(participants):
            for method, ie, nt in (("vahr", 111, 142), ("keyboard", 175, 59)):
                for trial in range(1, trials + 1):
                    i, n = rng.gauss(ie, 20), rng.gauss(nt, 20)
                    row = {
                        "participant": f"P{p:02d}",
                        "method": method,
                        "trial": trial,
                        "interaction_time_s": round(i, 1),
                        "neglect_time_s": round(n, 1),
                        "task_time_s": round(i + n + rng.uniform(0, 2), 1),
                        "puzzle_parts": rng.randint(3, 12)
                        if method == "vahr"
                        else rng.randint(0, 6),
                    }
                    for item in ITEMS:
                        row[item] = rng.randint(1, 21)
                    writer.writerow(row)
    return path


def column(path: Path, method: str, name: str) -> list[float]:
    with path.open() as stream:
        return [float(r[name]) for r in csv.DictReader(stream) if r["method"] == method]


def test_p_values_match_scipys_one_way_anova(tmp_path: Path) -> None:
    # scipy is the reference, imported here: every worker collects this module
    from scipy import stats

    # Given a generated data set of 8 participants x 2 methods x 3 trials
    data = generated_csv(tmp_path / "results.csv")
    # When the report is built
    report = build_report(read_csv(data))
    # Then every p-value is f_oneway's, with method as the factor over all rows
    for metric, name in [
        ("interaction_time", "interaction_time_s"),
        ("neglect_time", "neglect_time_s"),
        ("time_taken", "task_time_s"),
        ("puzzle_parts", "puzzle_parts"),
    ]:
        want = stats.f_oneway(column(data, "vahr", name), column(data, "keyboard", name)).pvalue
        assert report["objective"][metric]["p_value"] == pytest.approx(want, rel=1e-12)
    for item in ITEMS:
        groups = [[(v - 1) * 5 for v in column(data, m, item)] for m in ("vahr", "keyboard")]
        want = stats.f_oneway(*groups).pvalue
        assert report["subjective"][item]["p_value"] == pytest.approx(want, rel=1e-12)
    # and RAD and fan-out are computed per row, then averaged
    ie, nt = column(data, "vahr", "interaction_time_s"), column(data, "vahr", "neglect_time_s")
    time_taken = column(data, "vahr", "task_time_s")
    rads = [i / (i + n) for i, n in zip(ie, nt, strict=True)]
    assert report["objective"]["rad"]["means"]["vahr"] == pytest.approx(sum(rads) / len(rads))
    fan_outs = [t / r for t, r in zip(time_taken, rads, strict=True)]
    assert report["objective"]["fan_out"]["means"]["vahr"] == pytest.approx(
        sum(fan_outs) / len(fan_outs)
    )
    assert (
        report["objective"]["rad"]["means"]["vahr"]
        < report["objective"]["rad"]["means"]["keyboard"]
    )


def test_subjective_means_are_percent(tmp_path: Path) -> None:
    data = generated_csv(tmp_path / "results.csv", participants=2, trials=1)
    report = build_report(read_csv(data))
    levels = column(data, "keyboard", "trust")
    assert report["subjective"]["trust"]["means"]["keyboard"] == pytest.approx(
        sum((v - 1) * 5 for v in levels) / len(levels)
    )


def test_tlx_change_per_trial(tmp_path: Path) -> None:
    data = generated_csv(tmp_path / "results.csv", participants=3, trials=3)
    report = build_report(read_csv(data))
    by_trial = report["tlx_by_trial"]["mental"]["vahr"]
    assert set(by_trial) == {"1", "2", "3"}
    assert report["tlx_change"]["mental"]["vahr"]["1->2"] == pytest.approx(
        by_trial["2"] - by_trial["1"]
    )
    first = [
        (v - 1) * 5
        for v, t in zip(column(data, "vahr", "mental"), column(data, "vahr", "trial"), strict=True)
        if t == 1
    ]
    assert by_trial["1"] == pytest.approx(sum(first) / len(first))


def test_one_method_alone_has_no_p_value(tmp_path: Path) -> None:
    data = generated_csv(tmp_path / "results.csv", participants=2)
    rows = [r for r in read_csv(data) if r.method == "vahr"]
    report = build_report(rows)
    assert report["methods"] == ["vahr"]
    assert report["objective"]["rad"]["p_value"] is None


def test_the_report_files_are_written(tmp_path: Path) -> None:
    data = generated_csv(tmp_path / "results.csv", participants=3, trials=2)
    out = tmp_path / "out"
    write_report(read_csv(data), out, source=str(data))
    report = json.loads((out / "report.json").read_text())
    assert set(report["objective"]) == {
        "interaction_time",
        "neglect_time",
        "rad",
        "fan_out",
        "puzzle_parts",
        "time_taken",
    }
    assert set(report["subjective"]) == set(ITEMS)
    markdown = (out / "report.md").read_text()
    assert "| RAD = IE / (IE + NT) |" in markdown
    assert "| | vahr | keyboard | p (one-way ANOVA) | within-subjects test | p |" in markdown
    for stem in ("subjective", "tlx_by_trial", "objective", "trial_change"):
        assert (out / f"{stem}.png").read_bytes()[:8] == PNG_MAGIC
        assert b"<svg" in (out / f"{stem}.svg").read_bytes()[:1000]
        assert f"![{stem}.png]({stem}.png)" in markdown
    assert len(read_csv(out / "results.csv")) == 12
    # and each metric keeps the paper's means and p beside the within-subjects analysis
    rad = report["objective"]["rad"]
    assert {"means", "p_value", "within_subjects", "ci95"} <= set(rad)
    assert rad["within_subjects"]["test"] in ("paired_t", "wilcoxon")


@pytest.mark.parametrize(
    ("edit", "message"),
    [
        (lambda r: r.update(trust="22"), "row 2: trust: '22' is not a level; levels are 1 to 21"),
        (lambda r: r.update(neglect_time_s="soon"), "row 2: neglect_time_s 'soon' is not a number"),
        (lambda r: r.update(trial="0"), "row 2: trial must be 1 or more"),
        (lambda r: r.update(method=""), "row 2: method is empty"),
        (lambda r: r.update(interaction_time_s="0", neglect_time_s="0"), "RAD is undefined"),
    ],
)
def test_bad_csv_rows_are_named(tmp_path: Path, edit, message: str) -> None:  # type: ignore[no-untyped-def]
    row = {c: "1" for c in COLUMNS} | {"participant": "P1", "method": "vahr"}
    edit(row)
    path = tmp_path / "bad.csv"
    with path.open("w", newline="") as stream:
        writer = csv.DictWriter(stream, fieldnames=COLUMNS)
        writer.writeheader()
        writer.writerow(row)
    with pytest.raises(VahrError) as caught:
        read_csv(path)
    assert message in str(caught.value)


def test_runs_without_a_questionnaire_leave_its_columns_empty(tmp_path: Path) -> None:
    # Given a results CSV whose runs have no questionnaire (simulated participants)
    data = generated_csv(tmp_path / "results.csv", participants=3, trials=1)
    lines = data.read_text().splitlines()
    blank = [",".join(line.split(",")[:7] + [""] * len(ITEMS)) for line in lines[1:]]
    data.write_text("\n".join([lines[0], *blank]) + "\n")
    # When the report is made, Then it has the objective results and no subjective figures
    out = tmp_path / "out"
    report = write_report(read_csv(data), out)
    assert report["rows_with_questionnaire"] == 0
    assert report["objective"]["rad"]["means"]
    assert (out / "objective.png").exists() and not (out / "subjective.png").exists()
    assert "No run has questionnaire answers" in (out / "report.md").read_text()
    # while a questionnaire half filled in is refused, naming the empty items
    half = [",".join(line.split(",")[:7] + ["5"] * 4 + [""] * 4) for line in lines[1:2]]
    data.write_text("\n".join([lines[0], *half]) + "\n")
    with pytest.raises(VahrError, match="row 2: the questionnaire is incomplete"):
        read_csv(data)


def test_missing_columns_are_named(tmp_path: Path) -> None:
    path = tmp_path / "bad.csv"
    path.write_text("participant,method,trial\nP1,vahr,1\n")
    with pytest.raises(VahrError, match="missing column"):
        read_csv(path)


def test_trust_adjusted_demand_is_averaged_per_row(tmp_path: Path) -> None:
    data = generated_csv(tmp_path / "results.csv", participants=3, trials=1)
    report = build_report(read_csv(data))
    ie, nt = (
        column(data, "keyboard", "interaction_time_s"),
        column(data, "keyboard", "neglect_time_s"),
    )
    trust = [(v - 1) * 5 / 100 for v in column(data, "keyboard", "trust")]
    want = [i + n * (1 - t) for i, n, t in zip(ie, nt, trust, strict=True)]
    assert report["trust_adjusted_rad"]["means"]["keyboard"] == pytest.approx(sum(want) / len(want))
    # A CSV carries no verdicts, so there are no success rates to pool
    assert report["success"] == {}
