"""docs/benchmarks.md is organised by area: every section a benchmark writes has its area,
a new one lands at the end of it, and rerunning a benchmark replaces only its own numbers."""

from __future__ import annotations

import re
import sys
from pathlib import Path

import pytest

BENCH = Path(__file__).resolve().parents[2] / "bench"
sys.path.insert(0, str(BENCH))

import _results  # noqa: E402


def test_every_section_a_benchmark_writes_has_an_area() -> None:
    # Given the section names the scripts under bench/ write
    written = {
        name
        for script in BENCH.glob("*.py")
        for name in re.findall(r'write_section\(\s*"([\w-]+)"', script.read_text())
    }
    assert len(written) > 25
    # Then each belongs to an area of the page
    for name in written:
        assert _results.area_of(name)


def test_the_page_has_every_area_and_every_section_in_its_area() -> None:
    page = _results.RESULTS_FILE.read_text()
    for marker, heading, names in _results.AREAS:
        start, end = f"<!-- area:{marker} -->", f"<!-- /area:{marker} -->"
        assert start in page and end in page, marker
        area = page.split(start, 1)[1].split(end, 1)[0]
        assert f"## {heading}\n" in area
        for name in names:
            if f"<!-- bench:{name} -->" in page:
                assert f"<!-- bench:{name} -->" in area, f"{name} is outside {marker}"


def test_a_new_section_lands_at_the_end_of_its_area_and_a_rerun_replaces_it(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    # Given an empty page
    page = tmp_path / "benchmarks.md"
    monkeypatch.setattr(_results, "RESULTS_FILE", page)
    # When two fleet figures and a station figure are written, then one fleet figure again
    _results.write_section("fanout", "Fan-out", "first")
    _results.write_section("station", "Station", "paint")
    _results.write_section("dispatch", "Dispatch", "choose")
    _results.write_section("fanout", "Fan-out", "second")
    text = page.read_text()
    # Then the fleet's area holds both, in the order they came, with the latest numbers
    fleet = text.split("<!-- area:fleet -->", 1)[1].split("<!-- /area:fleet -->", 1)[0]
    assert fleet.index("bench:fanout") < fleet.index("bench:dispatch")
    assert "second" in fleet and "first" not in text
    assert "bench:station" not in fleet
    # And the station's area comes before the fleet's, as AREAS orders them
    assert text.index("<!-- area:station -->") < text.index("<!-- area:fleet -->")


def test_a_section_in_no_area_is_refused_and_the_page_is_unchanged(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    page = tmp_path / "benchmarks.md"
    monkeypatch.setattr(_results, "RESULTS_FILE", page)
    _results.write_section("fanout", "Fan-out", "first")
    before = page.read_text()
    with pytest.raises(ValueError, match="in no area"):
        _results.write_section("mystery", "Mystery", "42")
    assert page.read_text() == before
