"""The statistics of the report: the paper's one-way ANOVA and the within-subjects tests.

Every participant used both methods, so the design is within-subjects. The unit of analysis
is the participant: a participant's value for a method is the mean of their trials with it.

- `one_way_p`: the paper's analysis, a one-way ANOVA with method as the factor over every
  run (`scipy.stats.f_oneway`), kept to reproduce the paper.
- `within_subjects`: a repeated-measures ANOVA with participant as the subject
  (`statsmodels.stats.anova.AnovaRM`) and its partial eta squared; for two methods also
  the paired difference (first method minus second) with its 95 % confidence interval
  (`statsmodels` `DescrStatsW.tconfint_mean`), Cohen's d_z, a Shapiro-Wilk check of the
  differences' normality and, by it, a paired t-test (`scipy.stats.ttest_rel`) or a
  Wilcoxon signed-rank test (`scipy.stats.wilcoxon`).
- `paired_change`: the change of one method between two trials (the paper's figure of
  VAHR's trial 1 against trial 2), over the participants who did both.

Each result is plain JSON (floats, None where a statistic is undefined, with the reason).
scipy, statsmodels and pandas are imported inside the functions, so nothing else pays for
them.
"""

from __future__ import annotations

import math
import statistics
import warnings
from typing import Any

ALPHA = 0.05


def _finite(value: float | None) -> float | None:
    if value is None:
        return None
    value = float(value)
    return value if math.isfinite(value) else None


def one_way_p(groups: list[list[float]]) -> float | None:
    """One-way ANOVA p-value over the groups, or None where it is undefined."""
    from scipy import stats

    usable = [g for g in groups if g]
    if len(usable) < 2 or sum(len(g) for g in usable) <= len(usable):
        return None
    with warnings.catch_warnings():
        # Constant input makes F undefined; scipy warns and returns nan, reported as None.
        warnings.simplefilter("ignore")
        return _finite(stats.f_oneway(*usable).pvalue)


def mean_ci(values: list[float]) -> tuple[float, float, float] | None:
    """The mean and its 95 % t confidence interval, or None for fewer than two values."""
    if len(values) < 2:
        return None
    from statsmodels.stats.weightstats import DescrStatsW

    mean = statistics.fmean(values)
    if statistics.pstdev(values) == 0:
        return mean, mean, mean
    low, high = DescrStatsW(values).tconfint_mean(alpha=ALPHA)
    return mean, float(low), float(high)


def participant_means(rows: list[tuple[str, str, float]]) -> dict[str, dict[str, float]]:
    """(participant, method, value) rows -> {method: {participant: mean over trials}}."""
    collected: dict[str, dict[str, list[float]]] = {}
    for participant, method, value in rows:
        collected.setdefault(method, {}).setdefault(participant, []).append(value)
    return {
        method: {p: statistics.fmean(v) for p, v in by_participant.items()}
        for method, by_participant in collected.items()
    }


def rm_anova(by_method: dict[str, dict[str, float]], methods: list[str]) -> dict[str, Any]:
    """Repeated-measures ANOVA of one within factor (method), participant as subject."""
    import pandas as pd
    from statsmodels.stats.anova import AnovaRM

    complete = sorted(set.intersection(*(set(by_method.get(m, {})) for m in methods)))
    frame = pd.DataFrame(
        [(p, m, by_method[m][p]) for p in complete for m in methods],
        columns=["participant", "method", "value"],
    )
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # a zero residual gives F = inf or nan: None below
        table = AnovaRM(frame, "value", "participant", within=["method"]).fit().anova_table
    f, df1, df2, p = (float(table.iloc[0][c]) for c in ("F Value", "Num DF", "Den DF", "Pr > F"))
    partial = f * df1 / (f * df1 + df2) if math.isfinite(f) else None
    return {
        "F": _finite(f),
        "df": [df1, df2],
        "p_value": _finite(p),
        "partial_eta_squared": _finite(partial),
    }


def _paired(differences: list[float]) -> dict[str, Any]:
    """The paired comparison of two methods from the per-participant differences."""
    from scipy import stats

    n = len(differences)
    result: dict[str, Any] = {"mean_difference": statistics.fmean(differences)}
    interval = mean_ci(differences)
    result["ci95"] = [interval[1], interval[2]] if interval else None
    spread = statistics.stdev(differences) if n > 1 else 0.0
    if spread == 0:
        result.update(
            normality=None,
            test=None,
            statistic=None,
            p_value=None,
            cohens_dz=None,
            reason="every participant's difference is the same: no test is defined",
        )
        return result
    result["cohens_dz"] = result["mean_difference"] / spread
    normal = True
    if n >= 3:
        shapiro = stats.shapiro(differences)
        normal = bool(shapiro.pvalue >= ALPHA)
        result["normality"] = {
            "test": "shapiro-wilk",
            "W": _finite(shapiro.statistic),
            "p_value": _finite(shapiro.pvalue),
            "normal": normal,
        }
    else:
        result["normality"] = None  # too few participants to check; the t-test is used
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        if normal:
            test = stats.ttest_1samp(differences, 0.0)
            result.update(test="paired_t", statistic=_finite(test.statistic))
            result["df"] = n - 1
        else:
            test = stats.wilcoxon(differences)
            result.update(test="wilcoxon", statistic=_finite(test.statistic))
        result["p_value"] = _finite(test.pvalue)
    return result


def within_subjects(by_method: dict[str, dict[str, float]], methods: list[str]) -> dict[str, Any]:
    """The within-subjects analysis of one metric (see the module docstring)."""
    present = [m for m in methods if by_method.get(m)]
    complete = sorted(set.intersection(*(set(by_method[m]) for m in present))) if present else []
    result: dict[str, Any] = {"participants": len(complete), "methods": present}
    if len(present) < 2 or len(complete) < 2:
        result["test"] = None
        result["reason"] = "needs two methods and at least two participants who used both"
        return result
    result["rm_anova"] = rm_anova(by_method, present)
    if len(present) == 2:
        first, second = present
        result["difference"] = f"{first} - {second}"
        differences = [by_method[first][p] - by_method[second][p] for p in complete]
        result.update(_paired(differences))
    else:
        result["test"] = "rm_anova"
        result["p_value"] = result["rm_anova"]["p_value"]
    return result


def paired_change(before: dict[str, float], after: dict[str, float]) -> dict[str, Any]:
    """A method's change from one trial to the next, over the participants who did both."""
    both = sorted(set(before) & set(after))
    mean_before = statistics.fmean(before.values()) if before else None
    mean_after = statistics.fmean(after.values()) if after else None
    result: dict[str, Any] = {
        "means": [mean_before, mean_after],
        "participants": len(both),
        "change": None,
        "percent": None,
        "ci95": None,
        "p_value": None,
    }
    if mean_before is None or mean_after is None:
        return result
    result["change"] = mean_after - mean_before
    if mean_before != 0:
        result["percent"] = 100 * (mean_after - mean_before) / abs(mean_before)
    differences = [after[p] - before[p] for p in both]
    interval = mean_ci(differences)
    if interval is not None:
        result["ci95"] = [interval[1], interval[2]]
        if statistics.stdev(differences) > 0:
            from scipy import stats

            result["p_value"] = _finite(stats.ttest_1samp(differences, 0.0).pvalue)
    return result
