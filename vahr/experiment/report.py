"""The paper's tables from the results rows, with the analysis a within-subjects study needs.

`build_report(rows)` returns the report.json document. For each metric under `objective`
and each questionnaire item under `subjective` (the contract in docs/protocol.md, The command line):

    {"means": {METHOD: value}, "p_value": p, "sd": {...}, "n": {...},
     "ci95": {METHOD: [low, high]}, "within_subjects": {...}}

`means` and `p_value` are the paper's: means over every run and a one-way ANOVA with method
as the factor (`vahr.experiment.stats.one_way_p`, scipy's `f_oneway`). `ci95` is the 95 %
confidence interval of the mean over participants (each participant's mean over trials),
and `within_subjects` the repeated-measures analysis (`vahr.experiment.stats`). Beside them:
`trial_change` (each metric's and item's change between consecutive trials, per method),
`tlx_by_trial`, `tlx_change`, `trust_adjusted_rad`, `success` and counts. RAD and fan-out
are computed per row, then averaged.

`write_report(rows, out_dir)` writes report.json, report.md, results.csv and the figures
(`vahr.experiment.figures`).
"""

from __future__ import annotations

import json
import statistics
from typing import TYPE_CHECKING, Any

from vahr.experiment import stats
from vahr.experiment.figures import draw_figures, figure_names
from vahr.experiment.metrics import rate
from vahr.experiment.results import OBJECTIVE, ResultRow, write_csv
from vahr.experiment.tasks import METHODS
from vahr.experiment.tlx import ITEM_LABELS, ITEMS, SUBSCALES

if TYPE_CHECKING:
    from collections.abc import Callable
    from pathlib import Path

TEST_NAMES = {"paired_t": "paired t", "wilcoxon": "Wilcoxon", "rm_anova": "RM ANOVA"}


def methods_reported(rows: list[ResultRow]) -> list[str]:
    """The methods the rows hold: the paper's first, in its order, then any other by name."""
    present = {row.method for row in rows}
    return [m for m in METHODS if m in present] + sorted(present - set(METHODS))


def _summary(
    rows: list[ResultRow], methods: list[str], value: Callable[[ResultRow], float | None]
) -> dict[str, Any]:
    """One metric's object: the paper's means and one-way p, and the within-subjects view."""
    triples = [(r.participant, r.method, v) for r in rows if (v := value(r)) is not None]
    by_method = {m: [v for _, method, v in triples if method == m] for m in methods}
    per_participant = stats.participant_means(triples)
    ci95: dict[str, list[float] | None] = {}
    for m in methods:
        interval = stats.mean_ci(list(per_participant.get(m, {}).values()))
        ci95[m] = [interval[1], interval[2]] if interval else None
    return {
        "means": {m: statistics.fmean(v) for m, v in by_method.items() if v},
        "p_value": stats.one_way_p(list(by_method.values())),
        "sd": {m: statistics.stdev(v) if len(v) > 1 else 0.0 for m, v in by_method.items() if v},
        "n": {m: len(v) for m, v in by_method.items()},
        "ci95": ci95,
        "within_subjects": stats.within_subjects(per_participant, methods),
    }


def _trial_change(
    rows: list[ResultRow], methods: list[str], value: Callable[[ResultRow], float | None]
) -> dict[str, dict[str, Any]]:
    """{METHOD: {"1->2": paired change}} over consecutive trials."""
    trials = sorted({r.trial for r in rows})
    change: dict[str, dict[str, Any]] = {}
    for m in methods:
        per_trial = {
            t: {
                r.participant: v
                for r in rows
                if r.method == m and r.trial == t and (v := value(r)) is not None
            }
            for t in trials
        }
        present = [t for t in trials if per_trial[t]]
        change[m] = {
            f"{a}->{b}": stats.paired_change(per_trial[a], per_trial[b])
            for a, b in zip(present, present[1:], strict=False)
        }
    return change


def _item(item: str) -> Callable[[ResultRow], float | None]:
    return lambda r: r.tlx.percents()[item] if r.tlx is not None else None


def build_report(
    rows: list[ResultRow], *, source: str = "", simulated: bool = False
) -> dict[str, Any]:
    """The report.json document for `rows`."""
    methods = methods_reported(rows)
    objective = {
        metric: _summary(rows, methods, value) for metric, (_, _, value) in OBJECTIVE.items()
    }
    answered = [r for r in rows if r.tlx is not None]
    subjective = {item: _summary(answered, methods, _item(item)) for item in ITEMS}
    trial_change = {
        "objective": {
            metric: _trial_change(rows, methods, value)
            for metric, (_, _, value) in OBJECTIVE.items()
        },
        "subjective": {item: _trial_change(answered, methods, _item(item)) for item in ITEMS},
    }
    trials = sorted({r.trial for r in answered})
    by_trial: dict[str, dict[str, dict[str, float]]] = {}
    change: dict[str, dict[str, dict[str, float]]] = {}
    for item in SUBSCALES:
        by_trial[item], change[item] = {}, {}
        for m in methods:
            means = {}
            for trial in trials:
                values = [
                    r.tlx.percents()[item]
                    for r in answered
                    if r.method == m and r.trial == trial and r.tlx
                ]
                if values:
                    means[str(trial)] = statistics.fmean(values)
            by_trial[item][m] = means
            ordered = sorted(means, key=int)
            change[item][m] = {
                f"{a}->{b}": means[b] - means[a] for a, b in zip(ordered, ordered[1:], strict=False)
            }
    success: dict[str, dict[str, Any]] = {}
    for kind in ("task", "command", "communication"):
        pooled = {}
        for m in methods:
            counted = [r.tallies[kind] for r in rows if r.method == m and r.tallies]
            total = sum(t for _, t in counted)
            if counted:
                pooled[m] = {
                    "successes": sum(s for s, _ in counted),
                    "total": total,
                    "success_rate": rate(sum(s for s, _ in counted), total),
                }
        if pooled:
            success[kind] = pooled
    return {
        "objective": objective,
        "subjective": subjective,
        "trust_adjusted_rad": _summary(answered, methods, lambda r: r.trust_adjusted),
        "success": success,
        "trial_change": trial_change,
        "tlx_by_trial": by_trial,
        "tlx_change": change,
        "methods": methods,
        "rows": len(rows),
        "rows_with_questionnaire": len(answered),
        "participants": len({r.participant for r in rows}),
        "trials": sorted({r.trial for r in rows}),
        "source": source,
        "simulated": simulated,
    }


def _fmt(value: float | None, unit: str = "") -> str:
    if value is None:
        return "n/a"
    if unit == "s":
        return f"{value:.1f} s"
    if unit == "%":
        return f"{value:.1f}"
    return f"{value:.2f}"


def _p(value: float | None) -> str:
    if value is None:
        return "n/a"
    return "< 0.001" if value < 0.001 else f"{value:.3f}"


def _within_cells(entry: dict[str, Any], unit: str) -> list[str]:
    """Test, p, effect size and the difference with its CI, for one metric's row."""
    within = entry["within_subjects"]
    test = TEST_NAMES.get(str(within.get("test")), "n/a")
    effect = "n/a"
    if within.get("cohens_dz") is not None:
        effect = f"d_z {within['cohens_dz']:.2f}"
    anova = within.get("rm_anova") or {}
    if anova.get("partial_eta_squared") is not None:
        effect += f", ηp² {anova['partial_eta_squared']:.2f}"
    difference = "n/a"
    if within.get("mean_difference") is not None:
        difference = _fmt(within["mean_difference"], unit)
        if within.get("ci95"):
            low, high = within["ci95"]
            difference += f" [{_fmt(low, unit)}, {_fmt(high, unit)}]"
    return [test, _p(within.get("p_value")), effect, difference]


def _table(
    title_rows: list[tuple[str, str, dict[str, Any]]], methods: list[str], difference: str
) -> list[str]:
    head = (
        "| | "
        + " | ".join(methods)
        + f" | p (one-way ANOVA) | within-subjects test | p | effect size | {difference} |"
    )
    lines = [head, "|---|" + "---|" * (len(methods) + 5)]
    for label, unit, entry in title_rows:
        cells = [_fmt(entry["means"].get(m), unit) for m in methods]
        cells += [_p(entry["p_value"]), *_within_cells(entry, unit)]
        lines.append(f"| {label} | " + " | ".join(cells) + " |")
    return lines


def render_markdown(report: dict[str, Any]) -> str:
    """report.md: the paper's Table II with the within-subjects analysis beside it."""
    methods: list[str] = report["methods"]
    difference = " - ".join(methods[:2]) + " [95% CI]" if len(methods) == 2 else "difference"
    lines = ["# Experiment report", ""]
    if report.get("simulated"):
        lines += [
            "**Simulated participants**: these numbers come from the simulated "
            "participant's model (docs/experiment.md), not from people.",
            "",
        ]
    lines += [
        f"{report['rows']} runs, {report['participants']} participant(s), "
        f"trials {', '.join(map(str, report['trials']))}"
        + (f", from {report['source']}" if report.get("source") else "")
        + ".",
        "",
        "## Objective results (Table II)",
        "",
        "Means per method over every run and the paper's one-way ANOVA; beside them the "
        "within-subjects test on each participant's mean over trials (paired t-test, or "
        "Wilcoxon signed-rank when Shapiro-Wilk rejects normal differences), Cohen's d_z, "
        "the repeated-measures partial eta squared, and the mean difference with its 95 % "
        "confidence interval. RAD and fan-out are computed per run, then averaged.",
        "",
    ]
    objective = [
        (label, unit, report["objective"][metric]) for metric, (label, unit, _) in OBJECTIVE.items()
    ]
    if report["trust_adjusted_rad"]["means"]:
        objective.append(
            (
                "Trust-adjusted demand = IE + NT x (1 - trust)",
                "s",
                report["trust_adjusted_rad"],
            )
        )
    lines += _table(objective, methods, difference)
    if report["success"]:
        lines += [
            "",
            "## Success rates",
            "",
            "Pooled over the runs' logs.",
            "",
            "| | " + " | ".join(methods) + " |",
            "|---|" + "---|" * len(methods),
        ]
        for kind, pooled in report["success"].items():
            cells = [
                f"{p['success_rate']:.0%} ({p['successes']}/{p['total']})"
                if m in pooled and p["success_rate"] is not None
                else "n/a"
                for m in methods
                for p in [pooled.get(m, {"success_rate": None})]
            ]
            lines.append(f"| {kind.capitalize()} success | " + " | ".join(cells) + " |")
    lines += ["", "## Subjective results", ""]
    if report["rows_with_questionnaire"]:
        lines += ["NASA-TLX and the two extra questions, as percent ((level - 1) x 5).", ""]
        items = [(ITEM_LABELS[i], "%", report["subjective"][i]) for i in ITEMS]
        lines += _table(items, methods, difference)
    else:
        lines += ["No run has questionnaire answers (simulated participants answer none)."]
    lines += [
        "",
        "## Change between trials",
        "",
        "Per method, the mean of each trial and the change to the next (percent of the "
        "first), with the 95 % CI of the paired change over participants who did both.",
        "",
    ]
    for group, labels in (
        ("objective", {m: (label, unit) for m, (label, unit, _) in OBJECTIVE.items()}),
        ("subjective", {i: (ITEM_LABELS[i], "%") for i in ITEMS}),
    ):
        for key, (label, unit) in labels.items():
            for m in methods:
                for step, body in report["trial_change"][group][key].get(m, {}).items():
                    if body["change"] is None:
                        continue
                    percent = f" ({body['percent']:+.0f} %)" if body["percent"] is not None else ""
                    interval = ""
                    if body["ci95"]:
                        interval = f", 95% CI [{_fmt(body['ci95'][0], unit)}, "
                        interval += f"{_fmt(body['ci95'][1], unit)}]"
                    before, after = body["means"]
                    lines.append(
                        f"- {label}, {m}, trial {step}: {_fmt(before, unit)} -> "
                        f"{_fmt(after, unit)}{percent}{interval}"
                    )
    lines += ["", "## Figures", ""]
    lines += [f"![{name}]({name})" for name in figure_names(report) if name.endswith(".png")]
    return "\n".join(lines) + "\n"


def write_report(
    rows: list[ResultRow], out_dir: Path, *, source: str = "", simulated: bool = False
) -> dict[str, Any]:
    """Write report.json, report.md, results.csv and the figures into `out_dir`."""
    out_dir.mkdir(parents=True, exist_ok=True)
    report = build_report(rows, source=source, simulated=simulated)
    (out_dir / "report.json").write_text(json.dumps(report, indent=2, sort_keys=False) + "\n")
    (out_dir / "report.md").write_text(render_markdown(report))
    write_csv(rows, out_dir / "results.csv")
    draw_figures(rows, report, out_dir)
    return report
