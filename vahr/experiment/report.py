"""The paper's tables and figures from the results rows: means, one-way ANOVA, charts.

`build_report(rows)` returns the report.json document:
`{"objective": {METRIC: {"means": {METHOD: value}, "p_value": p}}, "subjective": {ITEM:
{"means": {METHOD: percent}, "p_value": p}}}` plus `tlx_by_trial`, `tlx_change`, standard
deviations and counts. RAD and fan-out are computed per row, then averaged; each p-value
is a one-way ANOVA (`scipy.stats.f_oneway`) with method as the factor over every row (every
participant's every trial). It is None when it is undefined: fewer than two methods, a
method with no rows, or no variance at all.

`write_report(rows, out_dir)` writes report.json, report.md, results.csv and the figures.
matplotlib is imported here only, with the Agg backend, so nothing else pays for it.
"""

from __future__ import annotations

import json
import math
import statistics
import warnings
from typing import TYPE_CHECKING, Any

from vahr.experiment.metrics import rate
from vahr.experiment.results import ResultRow, write_csv
from vahr.experiment.tasks import METHODS
from vahr.experiment.tlx import ITEMS, SUBSCALES

if TYPE_CHECKING:
    from collections.abc import Callable
    from pathlib import Path

OBJECTIVE: dict[str, tuple[str, str, Callable[[ResultRow], float]]] = {
    "interaction_time": ("Interaction time (IE)", "s", lambda r: r.interaction_time_s),
    "neglect_time": ("Neglect time (NT)", "s", lambda r: r.neglect_time_s),
    "rad": ("RAD = IE / (IE + NT)", "", lambda r: r.rad),
    "fan_out": ("Fan-out = time / RAD", "s", lambda r: r.fan_out),
    "puzzle_parts": ("Solved puzzle parts", "", lambda r: float(r.puzzle_parts)),
    "time_taken": ("Time taken", "s", lambda r: r.task_time_s),
}
ITEM_LABELS = {
    "mental": "Mental demand",
    "physical": "Physical demand",
    "temporal": "Temporal demand",
    "performance": "Performance",
    "effort": "Effort",
    "frustration": "Frustration",
    "confidence": "Confidence",
    "trust": "Trust",
}
FIGURES = ("subjective.png", "tlx_by_trial.png", "objective.png")


def method_order(rows: list[ResultRow]) -> list[str]:
    present = {row.method for row in rows}
    return [m for m in METHODS if m in present] + sorted(present - set(METHODS))


def anova_p(groups: list[list[float]]) -> float | None:
    """One-way ANOVA p-value over the groups, or None where it is undefined."""
    from scipy import stats

    usable = [g for g in groups if g]
    if len(usable) < 2 or sum(len(g) for g in usable) <= len(usable):
        return None
    with warnings.catch_warnings():
        # Constant input makes F undefined; scipy warns and returns nan, reported as None.
        warnings.simplefilter("ignore")
        p = float(stats.f_oneway(*usable).pvalue)
    return p if math.isfinite(p) else None


def _summary(values_by_method: dict[str, list[float]]) -> dict[str, Any]:
    return {
        "means": {m: statistics.fmean(v) for m, v in values_by_method.items() if v},
        "p_value": anova_p(list(values_by_method.values())),
        "sd": {
            m: statistics.stdev(v) if len(v) > 1 else 0.0 for m, v in values_by_method.items() if v
        },
        "n": {m: len(v) for m, v in values_by_method.items()},
    }


def build_report(
    rows: list[ResultRow], *, source: str = "", simulated: bool = False
) -> dict[str, Any]:
    """The report.json document for `rows`."""
    methods = method_order(rows)
    objective = {
        metric: _summary({m: [value(r) for r in rows if r.method == m] for m in methods})
        for metric, (_, _, value) in OBJECTIVE.items()
    }
    answered = [r for r in rows if r.tlx is not None]
    subjective = {
        item: _summary(
            {
                m: [r.tlx.percents()[item] for r in answered if r.method == m and r.tlx]
                for m in methods
            }
        )
        for item in ITEMS
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
    trust_adjusted = _summary(
        {
            m: [v for r in rows if r.method == m and (v := r.trust_adjusted) is not None]
            for m in methods
        }
    )
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
        "trust_adjusted_rad": trust_adjusted,
        "success": success,
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


def render_markdown(report: dict[str, Any]) -> str:
    """report.md: the paper's Table II layout, the subjective results and the TLX trend."""
    methods: list[str] = report["methods"]
    head = "| | " + " | ".join(methods) + " | p (ANOVA) |\n|---|" + "---|" * (len(methods) + 1)
    lines = ["# Experiment report", ""]
    if report.get("simulated"):
        lines += [
            "**Simulated participants**: these numbers come from the simulated "
            "participant's timing model, not from people.",
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
        "Means per method; RAD and fan-out are computed per run, then averaged.",
        "",
        head,
    ]
    for metric, (label, unit, _) in OBJECTIVE.items():
        entry = report["objective"][metric]
        cells = [_fmt(entry["means"].get(m), unit) for m in methods]
        lines.append(f"| {label} | " + " | ".join(cells) + f" | {_p(entry['p_value'])} |")
    trust = report["trust_adjusted_rad"]
    if trust["means"]:
        cells = [_fmt(trust["means"].get(m), "s") for m in methods]
        lines.append(
            "| Trust-adjusted demand = IE + NT x (1 - trust) | "
            + " | ".join(cells)
            + f" | {_p(trust['p_value'])} |"
        )
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
    lines += [
        "",
        "## Subjective results",
        "",
        "NASA-TLX and the two extra questions, as percent ((level - 1) x 5).",
        "",
        head,
    ]
    for item in ITEMS:
        entry = report["subjective"][item]
        cells = [
            _fmt(entry["means"].get(m), "%") + " %" if m in entry["means"] else "n/a"
            for m in methods
        ]
        lines.append(
            f"| {ITEM_LABELS[item]} | " + " | ".join(cells) + f" | {_p(entry['p_value'])} |"
        )
    lines += [
        "",
        "## NASA-TLX per trial",
        "",
        "Mean percent per trial, and the change between consecutive trials.",
        "",
    ]
    for item in SUBSCALES:
        per_method = report["tlx_by_trial"][item]
        for m in methods:
            means = per_method.get(m, {})
            if not means:
                continue
            trend = ", ".join(
                f"trial {t}: {v:.1f} %" for t, v in sorted(means.items(), key=lambda kv: int(kv[0]))
            )
            deltas = ", ".join(f"{k}: {v:+.1f}" for k, v in report["tlx_change"][item][m].items())
            lines.append(
                f"- {ITEM_LABELS[item]}, {m}: {trend}" + (f" ({deltas})" if deltas else "")
            )
    lines += ["", "## Figures", ""]
    lines += [f"![{name}]({name})" for name in FIGURES]
    return "\n".join(lines) + "\n"


def _sem(values: list[float]) -> float:
    return statistics.stdev(values) / math.sqrt(len(values)) if len(values) > 1 else 0.0


def draw_figures(rows: list[ResultRow], report: dict[str, Any], out_dir: Path) -> list[Path]:
    """The subjective-results bar chart, the TLX-per-trial lines and the objective bars."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    methods: list[str] = report["methods"]
    answered = [r for r in rows if r.tlx is not None]
    written: list[Path] = []
    suffix = " (simulated)" if report.get("simulated") else ""
    width = 0.8 / max(1, len(methods))

    fig, ax = plt.subplots(figsize=(10, 4.5))
    for index, m in enumerate(methods):
        values = [
            [r.tlx.percents()[item] for r in answered if r.method == m and r.tlx] for item in ITEMS
        ]
        xs = [i + (index - (len(methods) - 1) / 2) * width for i in range(len(ITEMS))]
        ax.bar(
            xs,
            [statistics.fmean(v) if v else 0 for v in values],
            width,
            yerr=[_sem(v) for v in values],
            capsize=3,
            label=m,
        )
    for i, item in enumerate(ITEMS):
        p = report["subjective"][item]["p_value"]
        if p is not None and p < 0.05:
            ax.annotate("*", (i, 102), ha="center")
    ax.set_xticks(range(len(ITEMS)), [ITEM_LABELS[i] for i in ITEMS], rotation=20)
    ax.set_ylim(0, 110)
    ax.set_ylabel("percent (mean, SEM)")
    ax.set_title("Subjective results" + suffix)
    ax.legend()
    fig.tight_layout()
    written.append(out_dir / "subjective.png")
    fig.savefig(written[-1], dpi=120)
    plt.close(fig)

    fig, axes = plt.subplots(2, 3, figsize=(11, 6), sharey=True)
    for ax, item in zip(axes.flat, SUBSCALES, strict=True):
        for m in methods:
            means = report["tlx_by_trial"][item].get(m, {})
            trials = sorted(means, key=int)
            ax.plot([int(t) for t in trials], [means[t] for t in trials], marker="o", label=m)
        ax.set_title(ITEM_LABELS[item])
        ax.set_xlabel("trial")
        ax.set_ylim(0, 100)
    axes.flat[0].set_ylabel("percent")
    axes.flat[3].set_ylabel("percent")
    axes.flat[0].legend()
    fig.suptitle("NASA-TLX per trial" + suffix)
    fig.tight_layout()
    written.append(out_dir / "tlx_by_trial.png")
    fig.savefig(written[-1], dpi=120)
    plt.close(fig)

    fig, (left, right) = plt.subplots(1, 2, figsize=(10, 4))
    ie = [report["objective"]["interaction_time"]["means"].get(m, 0) for m in methods]
    nt = [report["objective"]["neglect_time"]["means"].get(m, 0) for m in methods]
    left.bar(methods, ie, label="interaction time (IE)")
    left.bar(methods, nt, bottom=ie, label="neglect time (NT)")
    left.set_ylabel("seconds (mean)")
    left.set_title("Time taken = IE + NT" + suffix)
    left.legend()
    right.bar(methods, [report["objective"]["rad"]["means"].get(m, 0) for m in methods])
    right.set_ylim(0, 1)
    right.set_title("RAD" + suffix)
    fig.tight_layout()
    written.append(out_dir / "objective.png")
    fig.savefig(written[-1], dpi=120)
    plt.close(fig)
    return written


def write_report(
    rows: list[ResultRow], out_dir: Path, *, source: str = "", simulated: bool = False
) -> dict[str, Any]:
    """Write report.json, report.md, results.csv and the PNG figures into `out_dir`."""
    out_dir.mkdir(parents=True, exist_ok=True)
    report = build_report(rows, source=source, simulated=simulated)
    (out_dir / "report.json").write_text(json.dumps(report, indent=2, sort_keys=False) + "\n")
    (out_dir / "report.md").write_text(render_markdown(report))
    write_csv(rows, out_dir / "results.csv")
    draw_figures(rows, report, out_dir)
    return report
