"""The page's contract (static/contract.js): made from the structs, and checked against them."""

from __future__ import annotations

import json
import re
import typing
from typing import TYPE_CHECKING

import pytest

from vahr.station import contract
from vahr.station.page_messages import DRIVE_ENDS, PageMessage

if TYPE_CHECKING:
    from pathlib import Path


def typedef(text: str, name: str) -> str:
    """The JSDoc block that declares `name`."""
    found = re.search(r"/\*\*(?:(?!\*/).)*@typedef \{object\} " + name + r"\n.*?\*/", text, re.S)
    assert found, f"no typedef {name}"
    return found.group(0)


def test_the_committed_contract_is_the_one_the_structs_make() -> None:
    assert not contract.drifted(), "run `python -m vahr.station.contract` and commit the file"


def test_every_page_message_has_a_typedef_tagged_with_its_type() -> None:
    text = contract.render()
    for struct in typing.get_args(PageMessage):
        tag = struct.__struct_config__.tag
        assert f'@property {{"{tag}"}} type' in typedef(text, struct.__name__)
    assert "@typedef {SnapshotMessage|RobotsMessage|" in text


def test_a_property_is_optional_only_where_the_json_may_lack_it() -> None:
    text = contract.render()
    # An event leaves out what does not apply; in the conversation it names its robots
    assert "@property {string|null} [zone]" in typedef(text, "EventMessage")
    assert "@property {Array<string>} [robots]" in typedef(text, "EventMessage")
    # A turn always names its robots; the floor always has its walls (its struct keeps
    # defaults); a robot's reported state may lack any field (it is passed on as sent)
    assert "@property {Array<string>} robots" in typedef(text, "TurnMessage")
    assert "@property {Array<Segment>} walls" in typedef(text, "Floor")
    assert "[status]" in typedef(text, "Reported")
    # A robot's change holds only what changed: every field but the robot may be missing
    assert "@property {Reported} [reported]" in typedef(text, "RobotChange")
    assert "@property {string} thing" in typedef(text, "RobotChange")


def test_the_page_gets_the_stations_drive_ends() -> None:
    text = contract.render()
    assert f"export const DRIVE_ENDS = Object.freeze({json.dumps(sorted(DRIVE_ENDS))});" in text


def test_check_fails_on_a_stale_contract_until_it_is_written(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    stale = tmp_path / "contract.js"
    stale.write_text(contract.render().replace('"arrived", ', ""))
    monkeypatch.setattr(contract, "CONTRACT_FILE", stale)
    # When the file lacks what the structs say, the check fails and says what to run
    assert contract.main(["--check"]) == 1
    assert "python -m vahr.station.contract" in capsys.readouterr().err
    # Then writing it makes the check pass
    assert contract.main([]) == 0
    assert contract.main(["--check"]) == 0


@pytest.mark.parametrize(
    ("schema", "expected"),
    [
        ({"$ref": "#/$defs/Pose"}, "Pose"),
        ({"anyOf": [{"type": "string"}, {"type": "null"}]}, "string|null"),
        ({"enum": ["a", "b"]}, '"a"|"b"'),
        ({"type": "array", "items": {"type": "integer"}}, "Array<number>"),
        (
            {"type": "object", "additionalProperties": {"type": "boolean"}},
            "Record<string, boolean>",
        ),
        ({"type": "object"}, "Record<string, any>"),
        ({}, "any"),
    ],
)
def test_json_schema_types_become_jsdoc_types(schema: dict[str, object], expected: str) -> None:
    assert contract._js_type(schema) == expected
