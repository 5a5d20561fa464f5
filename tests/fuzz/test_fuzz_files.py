"""Fuzz: the files a user writes, `fleet.yaml` and the experiment's results CSV.

Properties: a fleet file loads or is refused with a `ProtocolError` naming the field; a
results CSV is read (and reported) or refused with one `VahrError` line naming the row or
column; nothing else escapes, so `robot-agent run --fleet` and `vahr report` always end
with a one-line reason, never a traceback.
"""

from __future__ import annotations

import copy
import csv
import io
from pathlib import Path
from typing import TYPE_CHECKING, Any

import msgspec
from hypothesis import given, settings
from hypothesis import strategies as st

from tests.fuzz.strategies import json_values, paths_in, scalars, text
from tests.fuzz.tally import TALLY, budget
from vahr.domain import Fleet
from vahr.errors import VahrError
from vahr.experiment.report import build_report
from vahr.experiment.results import COLUMNS, read_csv
from vahr.protocol import ProtocolError

if TYPE_CHECKING:
    import pytest

ROOT = Path(__file__).resolve().parents[2]
FLEET_DOCUMENT: dict[str, Any] = msgspec.yaml.decode((ROOT / "fleet.yaml").read_bytes())


@st.composite
def fleet_texts(draw: st.DrawFn) -> bytes:
    kind = draw(st.sampled_from(["mutated", "mutated", "mutated", "json", "text", "bytes"]))
    if kind == "json":
        return msgspec.json.encode(draw(json_values()))
    if kind == "text":
        return draw(text).encode("utf-8", "surrogatepass")
    if kind == "bytes":
        return draw(st.binary(max_size=80))
    document = copy.deepcopy(FLEET_DOCUMENT)
    for _ in range(draw(st.integers(1, 3))):
        path = draw(st.sampled_from(paths_in(document)))
        parent: Any = document
        for step in path[:-1]:
            parent = parent[step]
        action = draw(st.sampled_from(["replace", "delete", "duplicate"]))
        if action == "delete" and isinstance(parent, dict):
            del parent[path[-1]]
        elif action == "duplicate" and isinstance(parent, list):
            parent.append(copy.deepcopy(parent[path[-1]]))
        else:
            parent[path[-1]] = draw(st.one_of(scalars, json_values(4)))
    return msgspec.yaml.encode(document)


@given(document=fleet_texts())
@settings(max_examples=budget(300))
def test_a_fleet_file_loads_or_is_refused_naming_the_field(document: bytes) -> None:
    try:
        Fleet.from_yaml(document)
    except ProtocolError as err:
        # The field is the fleet's own (`robots.0.thing`) or the unknown key the file has.
        assert err.field and err.reason and "\n" not in str(err), err
        TALLY.rejected("fleet.yaml", err.field.split(".")[0])
        return
    TALLY.accepted("fleet.yaml")


GOOD_ROW = {
    "participant": "P01", "method": "voice", "trial": "1", "interaction_time_s": "12.5",
    "neglect_time_s": "40", "task_time_s": "60", "puzzle_parts": "3", "mental": "10",
    "physical": "3", "temporal": "8", "performance": "15", "effort": "9", "frustration": "4",
    "confidence": "17", "trust": "16",
}  # fmt: skip
CELLS = st.one_of(
    st.sampled_from(["", " ", "0", "1", "21", "22", "-1", "nan", "inf", "1e400", "3.5", "x"]),
    text,
)


@st.composite
def results_files(draw: st.DrawFn) -> bytes:
    kind = draw(st.sampled_from(["rows", "rows", "rows", "text", "bytes"]))
    if kind == "text":
        return draw(text).encode("utf-8", "surrogatepass")
    if kind == "bytes":
        return draw(st.binary(max_size=200))
    columns = list(COLUMNS)
    if draw(st.integers(0, 5)) == 0:
        columns.remove(draw(st.sampled_from(columns)))
    rows = []
    for index in range(draw(st.integers(0, 6))):
        row = dict(
            GOOD_ROW,
            participant=f"P{index % 3}",
            method=draw(st.sampled_from(["voice", "console", "x"])),
        )
        for _ in range(draw(st.integers(0, 2))):
            row[draw(st.sampled_from(columns))] = draw(CELLS)
        rows.append(row)
    stream = io.StringIO()
    writer = csv.DictWriter(stream, fieldnames=columns, extrasaction="ignore")
    writer.writeheader()
    writer.writerows(rows)
    raw = stream.getvalue()
    if draw(st.integers(0, 4)) == 0:  # a cut-off file, or a stray quote
        raw = raw[: draw(st.integers(0, len(raw)))] + draw(st.sampled_from(['"', "", ",,\n"]))
    return raw.encode("utf-8", "surrogatepass")


@given(content=results_files())
@settings(max_examples=budget(150))
def test_a_results_csv_is_reported_or_refused_in_one_line(
    tmp_path_factory: pytest.TempPathFactory, content: bytes
) -> None:
    path = tmp_path_factory.mktemp("csv") / "results.csv"
    path.write_bytes(content)
    try:
        rows = read_csv(path)
        report = build_report(rows, source=str(path))
    except VahrError as err:
        assert "\n" not in str(err) and str(err)
        TALLY.rejected("experiment CSV (vahr report)", str(err).split(":")[0][:20])
        return
    assert report["rows"] == len(rows)
    msgspec.json.encode(report)  # the report.json that would be written
    TALLY.accepted("experiment CSV (vahr report)")
