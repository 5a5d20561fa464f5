"""The report's figures, each written as PNG and SVG.

- `objective`: one panel per objective metric: every participant's value per method (the
  mean of their trials, joined by a line across methods), with the mean and its 95 %
  confidence interval;
- `subjective`: the NASA-TLX subscales and the two extra questions as grouped bars (mean
  per method, 95 % CI error bars), as in the paper;
- `tlx_by_trial`: each subscale per trial and method;
- `trial_change`: the change from one trial to the next in percent, per method, for the
  objective metrics and (when answered) the questionnaire items, as the paper's figure of
  VAHR's trial 1 against trial 2.

Legends sit outside the axes so they never cover data. matplotlib is imported here only,
with the Agg backend.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from vahr.experiment import stats
from vahr.experiment.results import OBJECTIVE
from vahr.experiment.tlx import ITEM_LABELS, ITEMS, SUBSCALES

if TYPE_CHECKING:
    from pathlib import Path

    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

    from vahr.experiment.results import ResultRow

FORMATS = ("png", "svg")
METHOD_LABELS = {"vahr": "VAHR (voice)", "keyboard": "keyboard and mouse"}


def figure_names(report: dict[str, Any]) -> list[str]:
    """The files `draw_figures` writes for `report`."""
    stems = ["objective", "trial_change"]
    if report.get("rows_with_questionnaire"):
        stems += ["subjective", "tlx_by_trial"]
    return [f"{stem}.{fmt}" for stem in stems for fmt in FORMATS]


def _label(method: str) -> str:
    return METHOD_LABELS.get(method, method)


def _save(fig: Figure, out_dir: Path, stem: str) -> list[Path]:
    written = []
    for fmt in FORMATS:
        path = out_dir / f"{stem}.{fmt}"
        fig.savefig(path, dpi=120, bbox_inches="tight")
        written.append(path)
    return written


def _objective(rows: list[ResultRow], report: dict[str, Any], suffix: str) -> Figure:
    import matplotlib.pyplot as plt

    methods: list[str] = report["methods"]
    fig, axes = plt.subplots(2, 3, figsize=(11, 6.5))
    for ax, (metric, (label, unit, value)) in zip(axes.flat, OBJECTIVE.items(), strict=True):
        per = stats.participant_means([(r.participant, r.method, value(r)) for r in rows])
        people = sorted({p for m in methods for p in per.get(m, {})})
        for person in people:
            xs = [i for i, m in enumerate(methods) if person in per.get(m, {})]
            ys = [per[methods[i]][person] for i in xs]
            ax.plot(xs, ys, color="0.75", linewidth=0.8, zorder=1)
            ax.scatter(xs, ys, s=14, color="0.45", zorder=2, label="_participant")
        for i, m in enumerate(methods):
            interval = stats.mean_ci(list(per.get(m, {}).values()))
            if interval is None:
                continue
            mean, low, high = interval
            ax.errorbar(
                i + 0.18,
                mean,
                yerr=[[mean - low], [high - mean]],
                fmt="o",
                color=f"C{i}",
                capsize=4,
                markersize=7,
                zorder=3,
            )
        within = report["objective"][metric]["within_subjects"]
        p = within.get("p_value")
        note = f"within-subjects p = {p:.3g}" if p is not None else "within-subjects p n/a"
        ax.set_title(f"{label}{' (' + unit + ')' if unit else ''}\n{note}", fontsize=9)
        ax.set_xticks(range(len(methods)), [_label(m) for m in methods], fontsize=8)
        ax.set_xlim(-0.5, len(methods) - 0.5)
        ax.margins(y=0.15)
    handles = [
        plt.Line2D([], [], color="0.45", marker="o", linestyle="-", markersize=4),
        plt.Line2D([], [], color="C0", marker="o", linestyle="", markersize=7),
    ]
    fig.legend(
        handles,
        ["a participant (mean of trials), across methods", "mean and 95% CI over participants"],
        loc="lower center",
        ncol=2,
        frameon=False,
        bbox_to_anchor=(0.5, -0.02),
    )
    fig.suptitle("Objective results per participant" + suffix)
    fig.tight_layout(rect=(0, 0.05, 1, 1))
    return fig


def _grouped_bars(
    ax: Axes,
    keys: list[str],
    labels: list[str],
    methods: list[str],
    heights: dict[str, list[float | None]],
    errors: dict[str, list[tuple[float, float] | None]],
) -> None:
    width = 0.8 / max(1, len(methods))
    for index, m in enumerate(methods):
        xs = [i + (index - (len(methods) - 1) / 2) * width for i in range(len(keys))]
        values = [h if h is not None else 0.0 for h in heights[m]]
        low = [(e[0] if e else 0.0) for e in errors[m]]
        high = [(e[1] if e else 0.0) for e in errors[m]]
        ax.bar(xs, values, width, yerr=[low, high], capsize=3, label=_label(m), color=f"C{index}")
    ax.set_xticks(range(len(keys)), labels, rotation=20, ha="right", fontsize=8)


def _subjective(report: dict[str, Any], suffix: str) -> Figure:
    import matplotlib.pyplot as plt

    methods: list[str] = report["methods"]
    fig, ax = plt.subplots(figsize=(10, 4.5))
    heights: dict[str, list[float | None]] = {}
    errors: dict[str, list[tuple[float, float] | None]] = {}
    for m in methods:
        heights[m], errors[m] = [], []
        for item in ITEMS:
            entry = report["subjective"][item]
            mean = entry["means"].get(m)
            heights[m].append(mean)
            interval = entry["ci95"].get(m)
            errors[m].append(
                (max(0.0, mean - interval[0]), max(0.0, interval[1] - mean))
                if interval and mean is not None
                else None
            )
    _grouped_bars(ax, list(ITEMS), [ITEM_LABELS[i] for i in ITEMS], methods, heights, errors)
    ax.set_ylim(0, 100)
    ax.set_ylabel("percent (mean, 95% CI)")
    ax.set_title("NASA-TLX and the two extra questions" + suffix)
    ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), frameon=False)
    fig.tight_layout()
    return fig


def _tlx_by_trial(report: dict[str, Any], suffix: str) -> Figure:
    import matplotlib.pyplot as plt

    methods: list[str] = report["methods"]
    fig, axes = plt.subplots(2, 3, figsize=(11, 6.5), sharey=True)
    for ax, item in zip(axes.flat, SUBSCALES, strict=True):
        for index, m in enumerate(methods):
            means = report["tlx_by_trial"][item].get(m, {})
            trials = sorted(means, key=int)
            ax.plot(
                [int(t) for t in trials],
                [means[t] for t in trials],
                marker="o",
                color=f"C{index}",
                label=_label(m),
            )
        ax.set_title(ITEM_LABELS[item], fontsize=9)
        ax.set_xlabel("trial")
        ax.set_xticks(report["trials"])
        ax.set_ylim(0, 100)
    axes.flat[0].set_ylabel("percent")
    axes.flat[3].set_ylabel("percent")
    handles, labels = axes.flat[0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="lower center", ncol=len(methods), frameon=False)
    fig.suptitle("NASA-TLX per trial" + suffix)
    fig.tight_layout(rect=(0, 0.05, 1, 1))
    return fig


def _percent_changes(
    changes: dict[str, dict[str, Any]], keys: list[str], methods: list[str]
) -> tuple[dict[str, list[float | None]], dict[str, list[tuple[float, float] | None]]]:
    heights: dict[str, list[float | None]] = {}
    errors: dict[str, list[tuple[float, float] | None]] = {}
    for m in methods:
        heights[m], errors[m] = [], []
        for key in keys:
            steps = changes[key].get(m, {})
            body = steps.get("1->2") or next(iter(steps.values()), None)
            if body is None or body["percent"] is None:
                heights[m].append(None)
                errors[m].append(None)
                continue
            heights[m].append(body["percent"])
            before = abs(body["means"][0])
            if body["ci95"] and before:
                low, high = (100 * c / before for c in body["ci95"])
                errors[m].append(
                    (max(0.0, body["percent"] - low), max(0.0, high - body["percent"]))
                )
            else:
                errors[m].append(None)
    return heights, errors


def _trial_change(report: dict[str, Any], suffix: str) -> Figure:
    import matplotlib.pyplot as plt

    methods: list[str] = report["methods"]
    groups = [("objective", list(OBJECTIVE), [OBJECTIVE[k][0] for k in OBJECTIVE])]
    if report.get("rows_with_questionnaire"):
        groups.append(("subjective", list(ITEMS), [ITEM_LABELS[i] for i in ITEMS]))
    fig, axes = plt.subplots(1, len(groups), figsize=(6 * len(groups) + 1, 4.8), squeeze=False)
    for ax, (group, keys, labels) in zip(axes.flat, groups, strict=True):
        heights, errors = _percent_changes(report["trial_change"][group], keys, methods)
        _grouped_bars(ax, keys, labels, methods, heights, errors)
        ax.axhline(0, color="0.3", linewidth=0.8)
        ax.set_ylabel("change from the first trial to the next (%)")
        ax.set_title("Objective metrics" if group == "objective" else "Questionnaire", fontsize=9)
    handles, legend_labels = axes.flat[0].get_legend_handles_labels()
    fig.legend(handles, legend_labels, loc="lower center", ncol=len(methods), frameon=False)
    fig.suptitle("Change between trials (mean, 95% CI of the paired change)" + suffix)
    fig.tight_layout(rect=(0, 0.06, 1, 1))
    return fig


def draw_figures(rows: list[ResultRow], report: dict[str, Any], out_dir: Path) -> list[Path]:
    """Draw every figure of `figure_names(report)` into `out_dir`."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    suffix = " (simulated)" if report.get("simulated") else ""
    figures = [("objective", _objective(rows, report, suffix))]
    figures.append(("trial_change", _trial_change(report, suffix)))
    if report.get("rows_with_questionnaire"):
        figures.append(("subjective", _subjective(report, suffix)))
        figures.append(("tlx_by_trial", _tlx_by_trial(report, suffix)))
    written: list[Path] = []
    for stem, fig in figures:
        written += _save(fig, out_dir, stem)
        plt.close(fig)
    return written
