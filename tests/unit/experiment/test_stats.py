"""The within-subjects statistics equal statsmodels' and scipy's on a fixed data set.

The reference libraries are imported by the tests that use them: every test worker collects
this module, and importing pandas, scipy.stats and statsmodels costs about 3 s of CPU."""

from __future__ import annotations

import statistics

import pytest

from vahr.experiment.report import build_report
from vahr.experiment.results import ResultRow

# A fixed data set: 8 participants x 2 methods x 2 trials of interaction time (seconds).
IE = {
    "P1": {"vahr": (101, 96), "keyboard": (170, 160)},
    "P2": {"vahr": (120, 111), "keyboard": (181, 190)},
    "P3": {"vahr": (95, 99), "keyboard": (150, 148)},
    "P4": {"vahr": (130, 118), "keyboard": (169, 172)},
    "P5": {"vahr": (110, 104), "keyboard": (201, 188)},
    "P6": {"vahr": (99, 101), "keyboard": (140, 152)},
    "P7": {"vahr": (125, 119), "keyboard": (177, 171)},
    "P8": {"vahr": (104, 108), "keyboard": (163, 166)},
}


def rows(values: dict[str, dict[str, tuple[float, float]]]) -> list[ResultRow]:
    return [
        ResultRow(p, m, trial, ie, 60.0, ie + 60.0, 5, None)
        for p, by_method in values.items()
        for m, trials in by_method.items()
        for trial, ie in enumerate(trials, start=1)
    ]


def participant_means(values: dict[str, dict[str, tuple[float, float]]], m: str) -> list[float]:
    return [sum(v[m]) / len(v[m]) for v in values.values()]


def test_within_subjects_statistics_equal_statsmodels_and_scipy() -> None:
    import pandas as pd
    from scipy import stats
    from statsmodels.stats.anova import AnovaRM
    from statsmodels.stats.weightstats import DescrStatsW

    # When the report is built from the fixed data set
    within = build_report(rows(IE))["objective"]["interaction_time"]["within_subjects"]
    # Then the repeated-measures ANOVA is statsmodels' AnovaRM on the participant means
    frame = pd.DataFrame(
        [(p, m, sum(v[m]) / 2) for p, v in IE.items() for m in ("vahr", "keyboard")],
        columns=["participant", "method", "value"],
    )
    table = AnovaRM(frame, "value", "participant", within=["method"]).fit().anova_table
    f, df1, df2 = (float(table.iloc[0][c]) for c in ("F Value", "Num DF", "Den DF"))
    assert within["rm_anova"]["F"] == pytest.approx(f, rel=1e-12)
    assert within["rm_anova"]["df"] == [df1, df2] == [1.0, 7.0]
    assert within["rm_anova"]["p_value"] == pytest.approx(float(table.iloc[0]["Pr > F"]), rel=1e-9)
    assert within["rm_anova"]["partial_eta_squared"] == pytest.approx(f / (f + df2), rel=1e-12)
    # and, the differences being normal by Shapiro-Wilk, the paired t-test is scipy's
    voice, keyboard = participant_means(IE, "vahr"), participant_means(IE, "keyboard")
    differences = [a - b for a, b in zip(voice, keyboard, strict=True)]
    shapiro = stats.shapiro(differences)
    assert within["normality"]["p_value"] == pytest.approx(shapiro.pvalue, rel=1e-12)
    assert within["normality"]["normal"] is True and within["test"] == "paired_t"
    paired = stats.ttest_rel(voice, keyboard)
    assert within["statistic"] == pytest.approx(paired.statistic, rel=1e-12)
    assert within["p_value"] == pytest.approx(paired.pvalue, rel=1e-9)
    assert paired.statistic**2 == pytest.approx(f, rel=1e-9)  # one factor, two levels
    # with Cohen's d_z and the 95% confidence interval of the mean difference
    described = DescrStatsW(differences)
    assert within["cohens_dz"] == pytest.approx(described.mean / statistics.stdev(differences))
    assert within["mean_difference"] == pytest.approx(described.mean)
    assert within["ci95"] == pytest.approx(list(described.tconfint_mean(alpha=0.05)))
    assert within["difference"] == "vahr - keyboard" and within["participants"] == 8


def test_non_normal_differences_get_the_wilcoxon_signed_rank_test() -> None:
    from scipy import stats

    # Given differences with one far outlier (Shapiro-Wilk rejects normality)
    skewed = {p: {"vahr": v["vahr"], "keyboard": v["keyboard"]} for p, v in IE.items()}
    skewed["P8"] = {"vahr": (900, 910), "keyboard": (163, 166)}
    within = build_report(rows(skewed))["objective"]["interaction_time"]["within_subjects"]
    voice, keyboard = participant_means(skewed, "vahr"), participant_means(skewed, "keyboard")
    differences = [a - b for a, b in zip(voice, keyboard, strict=True)]
    assert stats.shapiro(differences).pvalue < 0.05
    assert within["normality"]["normal"] is False and within["test"] == "wilcoxon"
    assert within["p_value"] == pytest.approx(stats.wilcoxon(differences).pvalue, rel=1e-12)


def test_the_one_way_anova_stays_scipys_over_every_run() -> None:
    from scipy import stats

    report = build_report(rows(IE))
    voice = [ie for v in IE.values() for ie in v["vahr"]]
    keyboard = [ie for v in IE.values() for ie in v["keyboard"]]
    assert report["objective"]["interaction_time"]["p_value"] == pytest.approx(
        stats.f_oneway(voice, keyboard).pvalue, rel=1e-12
    )


def test_the_change_between_trials_is_paired_per_participant() -> None:
    from scipy import stats

    change = build_report(rows(IE))["trial_change"]["objective"]["interaction_time"]["vahr"]
    first = [v["vahr"][0] for v in IE.values()]
    second = [v["vahr"][1] for v in IE.values()]
    body = change["1->2"]
    assert body["means"] == pytest.approx([sum(first) / 8, sum(second) / 8])
    assert body["percent"] == pytest.approx(100 * (sum(second) - sum(first)) / sum(first))
    assert body["p_value"] == pytest.approx(stats.ttest_rel(second, first).pvalue, rel=1e-9)


def test_one_participant_gives_no_within_subjects_test() -> None:
    within = build_report(rows({"P1": IE["P1"]}))["objective"]["rad"]["within_subjects"]
    assert within["test"] is None and "at least two participants" in within["reason"]
