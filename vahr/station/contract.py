"""`python -m vahr.station.contract`: write the page's contract, or with `--check` report drift.

The page's side of the station's contract is `static/contract.js`: JSDoc typedefs for every
message the feed pushes (`vahr.protocol.station_topics.PageMessage`), for what the page posts as a
participant's input (`StationInput`) and for a robot's reported state, made from the
structs' JSON Schema (`msgspec.json.schema_components`), and the constants the page shares
with the feed (`DRIVE_ENDS`, `EXCHANGE_EVENTS`, how many commands and conversation entries
are kept). The station's scripts import those types and constants; `tsc` checks the scripts
against them, and `make lint` fails when the file and the structs differ.

A property is optional (`[name]`) when the JSON may lack it: a field with a default of a
struct that omits defaults, of a struct the page sends (the station fills in what it
lacks), or of a robot's reported state (passed on as the robot sent it).
"""

from __future__ import annotations

import argparse
import json
import sys
import textwrap
import typing
from pathlib import Path
from typing import Any

import msgspec

from vahr.protocol import EventKind, Reported
from vahr.protocol.station_topics import StationInput
from vahr.station.feed import COMMANDS_LIMIT, CONVERSATION_LIMIT
from vahr.station.page_messages import DRIVE_ENDS, EXCHANGE_EVENTS, ConversationEntry, PageMessage

CONTRACT_FILE = Path(__file__).with_name("static") / "contract.js"
REF_PREFIX = "#/$defs/"
# Unions the page names, in the order the file declares them.
UNIONS: tuple[tuple[str, Any], ...] = (
    ("PageMessage", PageMessage),
    ("ConversationEntry", ConversationEntry),
    ("StationInput", StationInput),
)
WIDTH = 96
HEADER = """\
// @ts-check
// The station's page contract: the messages the page is sent and sends, and the constants
// it shares with the station. Generated from vahr/station/page_messages.py by
// `python -m vahr.station.contract`: do not edit; change the structs and run it again.
"""


def render() -> str:
    """The text of `static/contract.js`."""
    schemas, components = msgspec.json.schema_components(
        [union for _, union in UNIONS] + [Reported], ref_template=REF_PREFIX + "{name}"
    )
    always = _always_present(PageMessage)
    parts = [HEADER]
    for name in sorted(components):
        parts.append(_typedef(name, components[name], always.get(name, frozenset())))
    for (name, _), schema in zip(UNIONS, schemas, strict=False):
        parts.append(f"/** @typedef {{{_js_type(schema)}}} {name} */\n")
    kinds = "|".join(json.dumps(kind) for kind in typing.get_args(EventKind))
    parts.append(f"/** What a robot can report it did. @typedef {{{kinds}}} EventKind */\n")
    parts.append(
        _constant(
            "DRIVE_ENDS",
            "Events after which a robot is no longer driving: the page stops moving it.",
            "ReadonlyArray<EventKind>",
            f"Object.freeze({json.dumps(sorted(DRIVE_ENDS))})",
        )
    )
    parts.append(
        _constant(
            "EXCHANGE_EVENTS",
            "The robots' own exchanges with the assistant, which the conversation shows.",
            "ReadonlyArray<EventKind>",
            f"Object.freeze({json.dumps(sorted(EXCHANGE_EVENTS))})",
        )
    )
    parts.append(
        _constant(
            "COMMANDS_LIMIT",
            "Commands whose acknowledgments the station follows; older ones are forgotten.",
            "number",
            str(COMMANDS_LIMIT),
        )
    )
    parts.append(
        _constant(
            "CONVERSATION_LIMIT",
            "Conversation entries the station keeps for a new page.",
            "number",
            str(CONVERSATION_LIMIT),
        )
    )
    return "\n".join(parts)


def _typedef(name: str, schema: dict[str, Any], always: frozenset[str]) -> str:
    required = set(schema.get("required", ())) | always
    lines = _comment_lines(schema.get("description", ""))
    lines.append(f"@typedef {{object}} {name}")
    for field, field_schema in schema.get("properties", {}).items():
        shown = field if field in required else f"[{field}]"
        lines.append(f"@property {{{_js_type(field_schema)}}} {shown}")
    return "/**\n" + "".join(f" * {line}".rstrip() + "\n" for line in lines) + " */\n"


def _comment_lines(description: str) -> list[str]:
    lines: list[str] = []
    for paragraph in description.replace("*/", "* /").split("\n\n"):
        words = " ".join(paragraph.split())
        if words:
            if lines:
                lines.append("")
            lines.extend(textwrap.wrap(words, WIDTH - 3))
    return lines


def _js_type(schema: dict[str, Any]) -> str:
    """The JSDoc (TypeScript) type of a JSON Schema as msgspec writes them."""
    if "$ref" in schema:
        return str(schema["$ref"]).removeprefix(REF_PREFIX)
    if "anyOf" in schema:
        return "|".join(dict.fromkeys(_js_type(option) for option in schema["anyOf"]))
    if "enum" in schema:
        return "|".join(json.dumps(value) for value in schema["enum"])
    if "const" in schema:
        return json.dumps(schema["const"])
    kind = schema.get("type")
    if kind == "string":
        return "string"
    if kind in ("integer", "number"):
        return "number"
    if kind in ("boolean", "null"):
        return str(kind)
    if kind == "array" and "prefixItems" in schema:
        # A tuple (a path's point, `[x, y]`).
        return f"[{', '.join(_js_type(item) for item in schema['prefixItems'])}]"
    if kind == "array":
        return f"Array<{_js_type(schema.get('items', {}))}>"
    if kind == "object":
        values = schema.get("additionalProperties")
        return f"Record<string, {_js_type(values) if isinstance(values, dict) else 'any'}>"
    if not schema:
        return "any"
    raise ValueError(f"no JSDoc type for the schema {schema}")


def _always_present(root: Any) -> dict[str, frozenset[str]]:
    """Per struct the station encodes (reachable from `root`) and that keeps its defaults,
    the fields its JSON always holds: all but those left UNSET."""
    found: dict[str, frozenset[str]] = {}
    seen: set[type] = set()

    def walk(info: msgspec.inspect.Type) -> None:
        if isinstance(info, msgspec.inspect.StructType):
            if info.cls in seen:
                return
            seen.add(info.cls)
            if not info.cls.__struct_config__.omit_defaults:
                found[info.cls.__name__] = frozenset(
                    field.encode_name for field in info.fields if field.default is not msgspec.UNSET
                )
            for field in info.fields:
                walk(field.type)
        elif isinstance(info, msgspec.inspect.UnionType):
            for option in info.types:
                walk(option)
        elif isinstance(info, msgspec.inspect.DictType):
            walk(info.key_type)
            walk(info.value_type)
        elif isinstance(info, msgspec.inspect.ListType | msgspec.inspect.SetType):
            walk(info.item_type)
        elif isinstance(info, msgspec.inspect.Metadata):
            walk(info.type)

    walk(msgspec.inspect.type_info(root))
    return found


def _constant(name: str, doc: str, js_type: str, value: str) -> str:
    return f"/** {doc} @type {{{js_type}}} */\nexport const {name} = {value};\n"


def drifted(path: Path | None = None) -> bool:
    """True when `path` (the page's contract.js) is not what `render` writes now."""
    try:
        return (path or CONTRACT_FILE).read_text(encoding="utf-8") != render()
    except FileNotFoundError:
        return True


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog="python -m vahr.station.contract",
        description="Write the station page's contract (static/contract.js) from the structs.",
    )
    parser.add_argument(
        "--check", action="store_true", help="write nothing; exit 1 if the file would change"
    )
    args = parser.parse_args(argv)
    if args.check:
        if drifted():
            print(
                f"{CONTRACT_FILE} is out of date with vahr/station/page_messages.py: run "
                "`python -m vahr.station.contract` and commit",
                file=sys.stderr,
            )
            return 1
        print("the page contract is up to date")
        return 0
    if drifted():
        CONTRACT_FILE.write_text(render(), encoding="utf-8")
        print(f"wrote {CONTRACT_FILE}")
    else:
        print("the page contract is up to date")
    return 0


if __name__ == "__main__":
    sys.exit(main())
