"""The HRI metrics of the paper, each a pure function citing its formula.

Interaction effort (IE) is the time the person spends interacting with the robots; neglect
time (NT, also called neglect tolerance) is the time the robots work on without attention.
How IE and NT are measured from the event log is documented in `vahr.experiment.measure`
and docs/experiment.md.
"""

from __future__ import annotations

import math


def _check_duration(name: str, value: float) -> None:
    if not math.isfinite(value) or value < 0:
        raise ValueError(f"{name} must be a finite number of seconds >= 0, got {value!r}")


def rad(interaction_effort_s: float, neglect_time_s: float) -> float:
    """Robot Attention Demand: RAD = IE / (IE + NT).

    The share of the time the robots demand the person's attention. With the paper's
    Table II averages, IE 111 s and NT 142 s give RAD 0.44 (voice) and IE 175 s and
    NT 59 s give 0.75 (keyboard and mouse).
    """
    _check_duration("interaction effort", interaction_effort_s)
    _check_duration("neglect time", neglect_time_s)
    total = interaction_effort_s + neglect_time_s
    if total == 0:
        raise ValueError("RAD is undefined when interaction effort and neglect time are both 0")
    return interaction_effort_s / total


def fan_out(task_time_s: float, attention_demand: float) -> float:
    """Fan-out: FO = total task time / RAD (in seconds, as the paper reports it).

    With the paper's averages, 254 s / 0.4387 = 579 s (reported 578 s) and
    234 s / 0.7479 = 313 s (reported 314 s). A lower RAD means the person could have
    attended to more robots in the same time, so fan-out grows.
    """
    _check_duration("task time", task_time_s)
    if not math.isfinite(attention_demand) or not 0 < attention_demand <= 1:
        raise ValueError(f"RAD must be in (0, 1] for fan-out, got {attention_demand!r}")
    return task_time_s / attention_demand


def trust_adjusted_rad(direct_interaction_s: float, neglect_time_s: float, trust: float) -> float:
    """Trust-adjusted attention demand: DIT + NT x (1 - Tr), in seconds.

    DIT is the direct interaction time (the interaction effort IE), NT the neglect time and
    Tr the person's trust in the robots in [0, 1] (the questionnaire's trust item as a
    fraction: percent / 100). A person who fully trusts the robots (Tr = 1) spends no
    attention on them while they work; one with no trust (Tr = 0) watches them the whole
    neglect time.
    """
    _check_duration("direct interaction time", direct_interaction_s)
    _check_duration("neglect time", neglect_time_s)
    if not math.isfinite(trust) or not 0 <= trust <= 1:
        raise ValueError(f"trust must be in [0, 1], got {trust!r}")
    return direct_interaction_s + neglect_time_s * (1 - trust)


def rate(successes: int, total: int) -> float | None:
    """A success (or failure) rate: successes / total, or None when nothing was attempted."""
    if successes < 0 or total < 0 or successes > total:
        raise ValueError(f"cannot take a rate of {successes} out of {total}")
    return successes / total if total else None
