"""How well the roles tagger's confidence is calibrated, and which threshold to ask below.

`python -m vahr.assistant.roles_calibration [SET]` reads a labelled set (the tuning set
by default; never a development set) and prints, for the utterances whose intent is
understood as labelled and whose slot roles the tagger read:

- a reliability table: the readings in bins of `Understanding.roles_confidence`, each bin's
  mean confidence beside the share of its readings that are right (every slot the
  expected value), and the log loss and Brier score of the confidence as that forecast;
- the sweep of `nlu.ROLES_CONFIDENCE_THRESHOLD` over `GRID`: right, wrong, asks and
  fallback on the whole set (a reading below the threshold is asked about), and the house
  rule's score, right less three times wrong.

The tuning set is not the taggers' training data, but the samples were written from it and a
few of its sentences are, with their values abstracted, a sample word for word. So the
readings are cross-validated: the set is cut into `FOLDS` folds, and each fold is read by
taggers retrained without any training sentence the CRF would read exactly as one of the
fold's (the same features). `--as-shipped` reads with the shipped taggers instead.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
from dataclasses import dataclass, replace
from pathlib import Path
from typing import TYPE_CHECKING

from vahr.assistant import roles
from vahr.assistant.evaluation import DEVELOPMENT_SET, LabelledSet, outcome
from vahr.assistant.nlu import InteractionModel
from vahr.assistant.simulator import strip_invocation
from vahr.domain.invocation import FALLBACK_INTENT

if TYPE_CHECKING:
    from collections.abc import Sequence

    from vahr.assistant.evaluation import LabelledUtterance
    from vahr.assistant.nlu import Understanding

TUNING_SET = DEVELOPMENT_SET.with_name("tuning-en-US.yaml")
FOLDS = 5
GRID = (0.0, 0.5, 0.6, 0.7, 0.8, 0.9, 0.95)
BINS = (0.0, 0.5, 0.6, 0.7, 0.8, 0.9, 0.95, 0.99, 1.0)
# A probability is kept this far from 0 and 1 in the log loss, so one sure mistake is a
# large loss but not an infinite one.
EPSILON = 1e-6


@dataclass(frozen=True)
class Reading:
    """One utterance as understood: its outcome were it acted on, and the roles confidence."""

    item: LabelledUtterance
    understood: Understanding
    # The outcome (`evaluation.outcome`) with the reading acted on whatever its confidence.
    acted: str

    @property
    def has_roles(self) -> bool:
        """The intent is the expected one and the tagger read the roles of its values."""
        return (
            self.understood.intent == self.item.intent and self.understood.intent != FALLBACK_INTENT
        )

    @property
    def right(self) -> bool:
        return self.acted == "right"

    def outcome_at(self, threshold: float) -> str:
        """The outcome with readings below `threshold` asked about instead of acted on."""
        unsure = self.understood.roles_confidence < threshold
        if self.understood.intent != FALLBACK_INTENT and unsure:
            return "asks"
        return self.acted


def read_all(model: InteractionModel, items: Sequence[LabelledUtterance]) -> list[Reading]:
    readings = []
    for item in items:
        understood = model.understand(strip_invocation(model.invocation_name, item.text))
        sure = replace(understood, roles_confidence=1.0)
        readings.append(Reading(item, understood, outcome(model, item, sure)))
    return readings


def cross_validated(
    model: InteractionModel, items: Sequence[LabelledUtterance], folds: int = FOLDS
) -> list[Reading]:
    """Each fold of `items` read by taggers that never read one of its sentences."""
    taggers = model.taggers
    by_index: dict[int, Reading] = {}
    for fold in range(folds):
        held_out = [(i, item) for i, item in enumerate(items) if i % folds == fold]
        seen: dict[str, set[str]] = {}
        for _, item in held_out:
            tagger = taggers.get(item.intent)
            if tagger is None:
                continue
            words, matches = model.find_slots(strip_invocation(model.invocation_name, item.text))
            seen.setdefault(item.intent, set()).add(json.dumps(tagger.features(words, matches)))
        retrained = {}
        for intent, features in seen.items():
            kept = [s for s in model.role_training[intent] if json.dumps(s[0]) not in features]
            retrained[intent], _ = roles.load_or_train(
                intent, model.intent_slots[intent], kept, None, model.role_lexicon
            )
        fold_model = model.with_taggers(retrained)
        for (index, _), reading in zip(
            held_out, read_all(fold_model, [item for _, item in held_out]), strict=True
        ):
            by_index[index] = reading
    return [by_index[index] for index in range(len(items))]


def reliability(readings: Sequence[Reading]) -> str:
    """The reliability table, log loss and Brier score of the readings with roles."""
    rated = [r for r in readings if r.has_roles]
    lines = [f"{'confidence':<12} {'n':>5} {'mean':>6} {'right':>6}"]
    for low, high in zip(BINS, BINS[1:], strict=False):
        inside = [
            r
            for r in rated
            if low <= r.understood.roles_confidence < high
            or (high == 1.0 and r.understood.roles_confidence == 1.0)
        ]
        if not inside:
            lines.append(f"[{low:.2f}, {high:.2f}) {0:>5}")
            continue
        mean = sum(r.understood.roles_confidence for r in inside) / len(inside)
        right = sum(r.right for r in inside) / len(inside)
        lines.append(f"[{low:.2f}, {high:.2f}) {len(inside):>5} {mean:>6.3f} {right:>6.3f}")
    loss = -sum(
        math.log(
            min(max(r.understood.roles_confidence, EPSILON), 1 - EPSILON)
            if r.right
            else 1 - min(max(r.understood.roles_confidence, EPSILON), 1 - EPSILON)
        )
        for r in rated
    ) / max(len(rated), 1)
    brier = sum((r.understood.roles_confidence - r.right) ** 2 for r in rated) / max(len(rated), 1)
    accuracy = sum(r.right for r in rated) / max(len(rated), 1)
    lines.append(
        f"{len(rated)} readings, {accuracy:.1%} right; log loss {loss:.3f}, Brier {brier:.3f}"
    )
    return "\n".join(lines)


def sweep(readings: Sequence[Reading], grid: Sequence[float] = GRID) -> str:
    """Right, wrong, asks and fallback over the whole set at each threshold of `grid`."""
    lines = [
        f"{'threshold':<10} {'right':>6} {'wrong':>6} {'asks':>6} {'fallback':>9} {'score':>6}"
    ]
    for threshold in grid:
        counts = {"right": 0, "wrong": 0, "asks": 0, "fallback": 0}
        for reading in readings:
            result = reading.outcome_at(threshold)
            # An out-of-domain sentence is right when it falls back (`evaluation`).
            if reading.item.intent == FALLBACK_INTENT and result == "fallback":
                result = "right"
            counts[result if result in counts else "asks"] += 1
        score = counts["right"] - 3 * counts["wrong"]
        lines.append(
            f"{threshold:<10.2f} {counts['right']:>6} {counts['wrong']:>6} {counts['asks']:>6} "
            f"{counts['fallback']:>9} {score:>6}"
        )
    return "\n".join(lines)


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("set", nargs="?", type=Path, default=TUNING_SET)
    parser.add_argument("--as-shipped", action="store_true", help="no cross-validation")
    args = parser.parse_args(argv)
    model = InteractionModel.load()
    items = LabelledSet.load(args.set).items()
    readings = read_all(model, items) if args.as_shipped else cross_validated(model, items)
    print(reliability(readings))
    print()
    print(sweep(readings))
    return 0


if __name__ == "__main__":
    sys.exit(main())
