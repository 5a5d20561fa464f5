"""The command line of people and the trail, without a running stack: `vahr up`'s banner
line on who may do what, and the one-line errors of `vahr say --user`, `vahr up --users`
and `vahr audit`."""

from __future__ import annotations

from typing import TYPE_CHECKING

from tests.unit.test_protocol_audit import entry
from vahr.cli import main
from vahr.commands.up import _who
from vahr.domain.people import People
from vahr.local.system import LocalSystem, SystemConfig
from vahr.plumbing.ports import free_port
from vahr.twin.trail_store import SqliteTrail

if TYPE_CHECKING:
    from pathlib import Path

    import pytest


def system(tmp_path: Path, **people: object) -> LocalSystem:
    config = SystemConfig(
        state_dir=tmp_path,
        mqtts_port=1,
        mqtt_port=None,
        api_port=2,
        **people,  # type: ignore[arg-type]
    )
    return LocalSystem(config)


def test_without_users_the_banner_says_anyone_may_do_everything(tmp_path: Path) -> None:
    assert _who(system(tmp_path)) == (
        "anyone may do everything, as a supervisor; nothing is confirmed first "
        "(--users FILE gives roles)"
    )


def test_with_users_the_banner_says_who_and_that_fleet_commands_are_confirmed(
    tmp_path: Path,
) -> None:
    people = People.from_yaml("users: [{id: a, name: A, role: operator}]")
    line = _who(system(tmp_path, people=people, users_file=tmp_path / "people.yaml"))
    assert line == (
        f"1 person from {tmp_path / 'people.yaml'}, anyone else a viewer; fleet-wide commands "
        "are confirmed with a yes first; nobody may sign in at the station (give people a "
        "token_sha256: vahr users token)"
    )


def test_the_experiment_turns_confirmation_off(tmp_path: Path) -> None:
    people = People.from_yaml("users: [{id: a, name: A, role: operator}]")
    paper = system(tmp_path, people=people, users_file=tmp_path / "p.yaml", confirm=False)
    assert paper.confirmation is False


def test_a_bad_user_id_is_one_line(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["say", "--user", "has a space", "where are the robots"]) == 2
    assert capsys.readouterr().err == (
        "vahr say: error: --user 'has a space': an Alexa id is 1 to 255 printable characters\n"
    )


def test_a_broken_users_file_stops_vahr_up_before_anything_starts(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    broken = tmp_path / "people.yaml"
    broken.write_text("users: [{id: a, name: A, role: admin}]\n")
    code = main(["up", "--users", str(broken), "--state-dir", str(tmp_path / "state")])
    assert code == 2
    assert capsys.readouterr().err.endswith(
        f"vahr up: error: --users {broken}: users.0.role: 'admin' is not a role; roles are "
        "viewer, operator, supervisor\n"
    )
    assert not (tmp_path / "state").exists()


def test_audit_with_nothing_running_is_one_line(capsys: pytest.CaptureFixture[str]) -> None:
    api = f"http://127.0.0.1:{free_port()}"
    assert main(["audit", "--api", api]) == 2
    assert capsys.readouterr().err.startswith(f"vahr audit: error: nothing answers at {api}")


def test_audit_reads_and_verifies_a_stopped_stacks_trail(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(["audit", "--state-dir", str(tmp_path)]) == 2
    assert "no audit trail here" in capsys.readouterr().err
    trail = SqliteTrail.in_state_dir(tmp_path)
    trail.append(entry("send all robots to zone a", "confirmed"))
    trail.close()
    assert main(["audit", "--state-dir", str(tmp_path)]) == 0
    assert capsys.readouterr().out == (
        "    1 2026-11-28T10:00:00.000Z alexa          Susan (supervisor): NavigateIntent "
        'confirmed -> placebot1, placebot2 "send all robots to zone a"\n'
    )
    assert main(["audit", "--state-dir", str(tmp_path), "--verify"]) == 0
    assert capsys.readouterr().out.startswith(
        "The audit trail is intact: 1 record; its head is record 1"
    )
