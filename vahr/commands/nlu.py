"""`vahr nlu "UTTERANCE"`: how the simulator understands an utterance (nothing runs), and
`vahr nlu --eval [FILE]`: accuracy on a labelled set (the shipped development set by default)."""

from __future__ import annotations

import json
from pathlib import Path
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    import argparse

    from vahr.assistant.nlu import InteractionModel, Understanding


def configure(parser: argparse.ArgumentParser) -> None:
    from vahr.assistant.evaluation import DEVELOPMENT_SET

    parser.add_argument(
        "utterance", nargs="?", help='what a person says, e.g. "send robot one to zone b"'
    )
    names = parser.add_mutually_exclusive_group()
    names.add_argument(
        "--model", type=Path, help="interaction model JSON (default: skill-package en-US)"
    )
    names.add_argument(
        "--fleet",
        type=Path,
        metavar="FILE",
        help="understand the names of this fleet file (its interaction model, generated in "
        "memory) instead",
    )
    parser.add_argument(
        "--eval",
        type=Path,
        nargs="?",
        const=DEVELOPMENT_SET,
        metavar="FILE",
        help="score a labelled set (YAML) instead; without FILE, the shipped development set "
        "of the locale",
    )
    parser.add_argument(
        "--locale",
        default="en-US",
        help="the language understood: en-US (default) or de-DE; its interaction model and "
        "understanding data",
    )
    parser.add_argument("--json", action="store_true", help="print JSON")


def run(args: argparse.Namespace) -> int:
    from vahr.assistant.evaluation import DEVELOPMENT_SET
    from vahr.assistant.localized import strip_invocation, supported
    from vahr.errors import VahrError

    supported(args.locale)
    if args.eval is not None:
        if args.utterance:
            raise VahrError("give an utterance or --eval, not both")
        labelled = args.eval
        if labelled == DEVELOPMENT_SET and args.locale != "en-US":
            labelled = DEVELOPMENT_SET.with_name(f"devset-{args.locale}.yaml")
        return _evaluate(_model(args), labelled, args.json)
    if args.utterance is None or not args.utterance.strip():
        raise VahrError("the utterance is empty")
    model = _model(args)
    said = strip_invocation(model.invocation_name, args.utterance, args.locale)
    understood = model.understand(said)
    printed = describe(understood)
    if args.json:
        print(json.dumps(printed))
        return 0
    print(f"intent      {understood.intent}  (confidence {understood.confidence:.2f})")
    if understood.best_guess:
        print(f"best guess  {understood.best_guess} (below the threshold)")
    if understood.sample:
        print(f"nearest     {understood.sample}")
    if understood.needs_confirmation:
        print(
            f"roles       unsure (confidence {understood.roles_confidence:.2f}): "
            "the simulator asks to confirm the reading before acting"
        )
    for name, slot in printed["slots"].items():
        if slot["value"] is None:
            print(f"slot        {name}: (empty)")
        elif slot["id"] is None:
            print(f"slot        {name}: {slot['value']!r} (ER_SUCCESS_NO_MATCH)")
        else:
            how = "" if slot["similarity"] == 100 else f", heard at {slot['similarity']:.0f}%"
            print(f"slot        {name}: {slot['value']!r} -> {slot['id']}{how}")
    return 0


def _model(args: argparse.Namespace) -> InteractionModel:
    from vahr.assistant.localized import load_model
    from vahr.assistant.nlu import InteractionModel
    from vahr.assistant.understanding import load_understanding

    if args.fleet is None:
        return load_model(args.locale, args.model)
    from vahr.commands.fleet_flag import read_fleet
    from vahr.skill_model.generator import build_interaction_model, build_locale_model

    fleet = read_fleet(args.fleet)
    if args.locale == "en-US":
        return InteractionModel(build_interaction_model(fleet))
    document = build_locale_model(fleet, args.locale)
    return InteractionModel(document, understanding=load_understanding(args.locale))


def describe(understood: Understanding) -> dict[str, Any]:
    """The JSON of `vahr nlu --json`: `intent` and `slots` {NAME: {value, id}} (a contract in
    docs/protocol.md), plus each slot's resolution, the confidence, the nearest sample and how sure
    the reading of which value fills which slot is (`roles_confidence`; below the threshold
    the simulator confirms the reading before acting: `needs_confirmation`)."""
    slots: dict[str, dict[str, Any]] = {}
    for name in understood.declared or tuple(understood.slots):
        value = understood.slots.get(name)
        if value is None:
            slots[name] = {"value": None, "id": None, "resolution": None}
            continue
        slots[name] = {
            "value": value.spoken,
            "id": value.id,
            "resolution": "ER_SUCCESS_MATCH" if value.resolved else "ER_SUCCESS_NO_MATCH",
            "name": value.canonical,
            "similarity": round(value.similarity, 1),
        }
    return {
        "intent": understood.intent,
        "slots": slots,
        "confidence": round(understood.confidence, 4),
        "best_guess": understood.best_guess,
        "sample": understood.sample,
        "roles_confidence": round(understood.roles_confidence, 4),
        "needs_confirmation": understood.needs_confirmation,
    }


def _evaluate(model: InteractionModel, file: Path, as_json: bool) -> int:
    from vahr.assistant.evaluation import LabelledSet, evaluate

    report = evaluate(model, LabelledSet.load(file))
    if as_json:
        print(json.dumps(report.to_json()))
        return 0
    print(report.table())
    misses = [scored for scored in report.scored if not scored.as_labelled]
    if misses:
        print("\nnot understood as labelled:")
    for scored in misses:
        got = scored.understood
        slots = {name: value.id for name, value in got.slots.items()}
        print(f"  {scored.outcome:<8} {scored.item.text!r} -> {got.intent} {slots}")
    return 0
