"""The paper's Table II as data, and a report set beside it.

`compare(report)` lines up each objective metric of a report with the paper's value per
method and says whether the direction of the difference between the methods (VAHR minus
keyboard and mouse) is the paper's. Only the paper's numbers live here; a rehearsal's are
whatever its model produced.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from vahr.experiment.results import OBJECTIVE


@dataclass(frozen=True)
class PaperValue:
    vahr: float
    keyboard: float
    p_value: float | None  # the paper's one-way ANOVA; None where it gives none


# Table II of the paper (means per method over both trials, one-way ANOVA p).
TABLE_II: dict[str, PaperValue] = {
    "interaction_time": PaperValue(111, 175, 2.9e-4),
    "neglect_time": PaperValue(142, 59, 2e-5),
    "rad": PaperValue(0.44, 0.75, 7.3e-7),
    "fan_out": PaperValue(578, 314, 6.3e-4),
    "puzzle_parts": PaperValue(13, 8, 3e-2),
    "time_taken": PaperValue(254, 234, None),
}


def _sign(value: float) -> int:
    return (value > 0) - (value < 0)


def compare(report: dict[str, Any]) -> list[dict[str, Any]]:
    """Each Table II metric: the paper's values, the report's, and whether the direction of
    the VAHR - keyboard difference agrees (None when the report lacks a method)."""
    lines = []
    for metric, paper in TABLE_II.items():
        entry = report["objective"][metric]
        means = entry["means"]
        ours = (means.get("vahr"), means.get("keyboard"))
        agrees = None
        if ours[0] is not None and ours[1] is not None:
            agrees = _sign(ours[0] - ours[1]) == _sign(paper.vahr - paper.keyboard)
        within = entry.get("within_subjects") or {}
        lines.append(
            {
                "metric": metric,
                "label": OBJECTIVE[metric][0],
                "paper": {"vahr": paper.vahr, "keyboard": paper.keyboard, "p_value": paper.p_value},
                "rehearsal": {
                    "vahr": ours[0],
                    "keyboard": ours[1],
                    "p_value": entry.get("p_value"),
                    "within_subjects_p": within.get("p_value"),
                },
                "direction_agrees": agrees,
            }
        )
    return lines


def _number(value: float | None) -> str:
    if value is None:
        return "n/a"
    if abs(value) >= 10 or float(value).is_integer():
        return f"{value:.0f}"
    return f"{value:.2f}"


def _p(value: float | None) -> str:
    return "n/a" if value is None else f"{value:.2g}"


def render_comparison(lines: list[dict[str, Any]]) -> str:
    """A Markdown table: metric, paper per method and p, rehearsal per method and p,
    whether the direction agrees."""
    out = [
        "| metric | paper VAHR | paper keyboard | paper p | rehearsal VAHR | "
        "rehearsal keyboard | rehearsal p (one-way / within) | direction agrees |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for line in lines:
        paper, ours = line["paper"], line["rehearsal"]
        agrees = {True: "yes", False: "no", None: "n/a"}[line["direction_agrees"]]
        out.append(
            f"| {line['label']} | {_number(paper['vahr'])} | {_number(paper['keyboard'])} | "
            f"{_p(paper['p_value'])} | {_number(ours['vahr'])} | {_number(ours['keyboard'])} | "
            f"{_p(ours['p_value'])} / {_p(ours['within_subjects_p'])} | {agrees} |"
        )
    return "\n".join(out) + "\n"
