"""The reader docs stand alone: no issue numbers, no citations of files outside the
repository, and the how-it-works pages stay short enough to read."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
# The pages for readers; docs/history keeps the record of how things got here, and the
# examples' notices cite their upstream sources as their licences ask.
READER_DOCS = sorted(
    path
    for path in [ROOT / "README.md", *(ROOT / "docs").rglob("*.md")]
    if "history" not in path.parts and "examples" not in path.parts
)
NOT_FOR_READERS = re.compile(
    r"\bissues? #?\d{1,3}\b|FIELD-NOTES|DESIGN\.md|PAPER-EXPERIMENT|\.\./shared/", re.IGNORECASE
)
# How each part works and how to extend it, in pages a reader finishes.
SHORT_PAGES = ("skill.md", "voice.md", "push-to-talk.md")
MAX_LINES = 500


@pytest.mark.parametrize("page", READER_DOCS, ids=lambda p: str(p.relative_to(ROOT)))
def test_a_reader_page_cites_no_issue_and_no_file_outside_the_repository(page: Path) -> None:
    found = NOT_FOR_READERS.findall(page.read_text())
    assert not found, f"{page.relative_to(ROOT)}: {found}"


@pytest.mark.parametrize("name", SHORT_PAGES)
def test_a_how_it_works_page_is_at_most_500_lines(name: str) -> None:
    lines = (ROOT / "docs" / name).read_text().count("\n")
    assert lines <= MAX_LINES, f"docs/{name} has {lines} lines"
