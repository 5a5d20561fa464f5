"""`vahr up --robots N` with a fleet file of one's own never adds robots the file does not
have: past its size it is refused in one line, before anything starts; the bundled fleet
still grows with `placebot3`... And a smaller fleet keeps its groups' names in every
language."""

from __future__ import annotations

from typing import TYPE_CHECKING

from tests.support.fleets import HOSPITAL
from vahr.cli import main
from vahr.domain import load_fleet
from vahr.domain.fleet import spoken_in
from vahr.local.robots import fleet_of

if TYPE_CHECKING:
    from pathlib import Path

    import pytest


def test_more_robots_than_a_fleet_file_has_is_refused(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    state = tmp_path / "state"
    code = main(["up", "--fleet", str(HOSPITAL), "--robots", "6", "--state-dir", str(state)])
    assert code == 2
    assert capsys.readouterr().err == (
        f"vahr up: error: --robots 6: {HOSPITAL} has 4 robots; give at most 4, "
        "or add robots to the file (or use --swarm N)\n"
    )
    assert not state.exists()


def test_the_first_robots_of_a_fleet_keep_the_groups_names_in_every_language() -> None:
    fleet = fleet_of(2, load_fleet(HOSPITAL))
    assert fleet.robot_things == ("hermes", "juno")
    [day_shift] = [group for group in fleet.groups if group.id == "day_shift"]
    assert spoken_in(day_shift, "de-DE")[0] == "tagschicht"


def test_the_bundled_fleet_still_grows() -> None:
    assert fleet_of(3).robot_things == ("placebot1", "placebot2", "placebot3")
