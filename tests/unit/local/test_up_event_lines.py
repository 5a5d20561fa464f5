"""`vahr up`'s live lines are for a person: progress is chatter (shown only at DEBUG), and
one command's same event from many robots is one line, so a fleet command to a swarm of
1,000 is a handful of lines, not tens of thousands. `--json` still prints every event."""

from __future__ import annotations

import json
from typing import TYPE_CHECKING

from vahr.commands.up import _EventPrinter
from vahr.protocol import Event, utc_now

if TYPE_CHECKING:
    import pytest


def events(kind: str, count: int, **fields: object) -> list[Event]:
    at = utc_now()
    return [
        Event(event=kind, thing=f"rover{n}", at=at, command_id="c0ffee00aa", action="navigate",
              **fields)  # type: ignore[arg-type]
        for n in range(1, count + 1)
    ]  # fmt: skip


def printed(printer: _EventPrinter, batch: list[Event], capsys: pytest.CaptureFixture[str]) -> str:
    printer.release()
    for event in batch:
        printer.print(event)
    printer.stop()
    return capsys.readouterr().out


def test_a_fleet_command_to_1000_robots_is_a_few_lines(capsys: pytest.CaptureFixture[str]) -> None:
    batch = [
        *events("accepted", 1000),
        *events("progress", 1000, zone="B", progress=0.5),
        *events("arrived", 1000, zone="B"),
    ]
    out = printed(_EventPrinter(as_json=False), batch, capsys).splitlines()
    assert len(out) == 2
    assert "1,000 robots accepted: rover1, rover2, rover3 and 997 more" in out[0]
    assert "1,000 robots arrived: rover1, rover2, rover3 and 997 more zone=B" in out[1]


def test_one_robots_event_is_its_own_line(capsys: pytest.CaptureFixture[str]) -> None:
    out = printed(_EventPrinter(as_json=False), events("arrived", 1, zone="B"), capsys)
    assert out.split()[1:3] == ["rover1", "arrived"]


def test_progress_is_shown_at_debug(capsys: pytest.CaptureFixture[str]) -> None:
    batch = events("progress", 1, zone="B", progress=0.5)
    assert "progress=50%" in printed(_EventPrinter(as_json=False, progress=True), batch, capsys)


def test_json_prints_every_event(capsys: pytest.CaptureFixture[str]) -> None:
    out = printed(_EventPrinter(as_json=True), events("progress", 5, progress=0.1), capsys)
    assert [json.loads(line)["thing"] for line in out.splitlines()] == [
        f"rover{n}" for n in range(1, 6)
    ]
