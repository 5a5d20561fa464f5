"""The Lambda bundle of a fleet on a map carries its zones' distance fields beside the
fleet file, where the dispatcher function reads them without numpy; a drawn floor's bundle
carries none. (The bundle's full build is tests/infra/test_infra_lambda_asset.py's.)"""

from __future__ import annotations

import shutil
from typing import TYPE_CHECKING

from infra import lambda_asset
from vahr.dispatch import STRAIGHT
from vahr.dispatch.grid_routes import GridRoutes, floor_routes
from vahr.domain import load_fleet

if TYPE_CHECKING:
    from pathlib import Path

TURTLEBOT3 = lambda_asset.REPO_ROOT / "docs/examples/turtlebot3_world/fleet.yaml"


def test_a_map_fleets_bundle_ranks_by_path_from_the_fields_beside_its_fleet(
    tmp_path: Path,
) -> None:
    # Given the bundle's fleet file as the build copies it (its map not beside it)
    bundled = tmp_path / lambda_asset.FLEET_IN_BUNDLE
    bundled.parent.mkdir(parents=True)
    shutil.copy2(TURTLEBOT3, bundled)
    # When the build writes the floor's distances
    lambda_asset._write_floor_distances(TURTLEBOT3, tmp_path)
    distances = tmp_path / lambda_asset.DISTANCES_IN_BUNDLE
    # Then they are small, and the function's reader takes them for the bundled fleet
    assert 0 < distances.stat().st_size < 100_000
    fleet = load_fleet(bundled)
    routes = floor_routes(fleet, str(distances))
    assert isinstance(routes, GridRoutes)
    # with every zone's path lengths: turtlebot two is nearest zone E by path
    zone_e = fleet.zone("E")
    lengths = {r.thing: routes.field(zone_e).distance(r.start.x, r.start.y) for r in fleet.robots}
    assert min(lengths, key=lengths.__getitem__) == "turtlebot2"
    # and the source hash counts the map's files (a new map builds a new bundle)
    assert set(lambda_asset._map_files(TURTLEBOT3)) == {
        TURTLEBOT3.parent / "map.yaml",
        TURTLEBOT3.parent / "map.pgm",
    }


def test_a_drawn_floors_bundle_has_no_distances(tmp_path: Path) -> None:
    lambda_asset._write_floor_distances(lambda_asset.REPO_ROOT / "fleet.yaml", tmp_path)
    assert not (tmp_path / lambda_asset.DISTANCES_IN_BUNDLE).exists()
    assert floor_routes(load_fleet(), str(tmp_path / "none.bin")) is STRAIGHT
