"""`vahr nlu "UTTERANCE"`: how the interaction model understands an utterance (nothing runs)."""

from __future__ import annotations

import json
from pathlib import Path
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    import argparse


def configure(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("utterance", help='what a person says, e.g. "send robot one to zone b"')
    parser.add_argument(
        "--model", type=Path, help="interaction model JSON (default: skill-package en-US)"
    )
    parser.add_argument("--json", action="store_true", help="print JSON")


def run(args: argparse.Namespace) -> int:
    from vahr.errors import VahrError
    from vahr.local.alexa.nlu import InteractionModel
    from vahr.local.alexa.simulator import strip_invocation

    if not args.utterance.strip():
        raise VahrError("the utterance is empty")
    model = InteractionModel.load(args.model)
    understood = model.understand(strip_invocation(model.invocation_name, args.utterance))
    slots = {
        name: {
            "value": value.spoken if (value := understood.slots.get(name)) else None,
            "id": value.id if value else None,
        }
        for name in understood.declared or tuple(understood.slots)
    }
    if args.json:
        print(
            json.dumps({"intent": understood.intent, "slots": slots, "sample": understood.sample})
        )
        return 0
    print(f"intent  {understood.intent}")
    if understood.sample:
        print(f"sample  {understood.sample}")
    for name, slot in slots.items():
        if slot["value"] is None:
            print(f"slot    {name}: (empty)")
        else:
            outcome = f"-> {slot['id']}" if slot["id"] else "(ER_SUCCESS_NO_MATCH)"
            print(f"slot    {name}: {slot['value']!r} {outcome}")
    return 0
