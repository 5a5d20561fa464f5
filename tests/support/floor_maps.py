"""Maps made for tests: map_server YAML and PGM files written the way map_saver writes them.

`write_map` writes any grid of shades (row 0 the map's top, as in the image); `two_rooms`
the edge case the issue names: two rooms side by side, a wall between them with a gap at
the top, and a fleet on it whose robot nearest zone A in a straight line is the farthest by
any path.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from pathlib import Path

# map_saver's shades: occupied, free, unknown.
OCCUPIED, FREE, UNKNOWN = 0, 254, 205
RESOLUTION = 0.05


def write_pgm(path: Path, shades: np.ndarray) -> Path:
    """A binary PGM (P5) of `shades` (uint8, row 0 the top)."""
    rows, columns = shades.shape
    path.write_bytes(f"P5\n{columns} {rows}\n255\n".encode() + shades.astype(np.uint8).tobytes())
    return path


def write_map(
    directory: Path,
    shades: np.ndarray,
    *,
    name: str = "map",
    resolution: float = RESOLUTION,
    origin: tuple[float, float] = (0.0, 0.0),
    extra: str = "",
) -> Path:
    """`name.pgm` and `name.yaml` in `directory`; the YAML's path."""
    write_pgm(directory / f"{name}.pgm", shades)
    yaml = directory / f"{name}.yaml"
    yaml.write_text(
        f"image: {name}.pgm\nresolution: {resolution}\n"
        f"origin: [{origin[0]}, {origin[1]}, 0.0]\nnegate: 0\n"
        f"occupied_thresh: 0.65\nfree_thresh: 0.196\n{extra}"
    )
    return yaml


@dataclass(frozen=True)
class TwoRooms:
    """Where the two rooms' map and fleet were written, and what a test needs to know."""

    map_file: Path
    fleet_file: Path
    # The wall between the rooms: x from `wall_left` to `wall_right`, y below `gap_bottom`.
    wall_left: float
    wall_right: float
    gap_bottom: float


# 10 m by 5 m: the wall at x 5 m rises from the floor to y 3.8 m; above it, the gap.
WIDTH_M, HEIGHT_M = 10.0, 5.0
WALL_X_M, WALL_HALF_M, GAP_BOTTOM_M = 5.0, 0.1, 3.8


def two_rooms(directory: Path, *, sim_fleet_extra: str = "") -> TwoRooms:
    """The map and a fleet on it: `left` starts in the west room 1.7 m from zone A through
    the wall; `right` starts in the east room, 4.4 m from zone A in a straight line and by
    path, while `left`'s path round the wall is about 8 m."""
    columns, rows = round(WIDTH_M / RESOLUTION), round(HEIGHT_M / RESOLUTION)
    shades = np.full((rows, columns), FREE, dtype=np.uint8)
    border = 2
    shades[:border, :] = shades[-border:, :] = OCCUPIED
    shades[:, :border] = shades[:, -border:] = OCCUPIED
    wall = slice(
        round((WALL_X_M - WALL_HALF_M) / RESOLUTION), round((WALL_X_M + WALL_HALF_M) / RESOLUTION)
    )
    # Image row 0 is the top (y = 5 m): the wall fills the rows below the gap.
    shades[round((HEIGHT_M - GAP_BOTTOM_M) / RESOLUTION) :, wall] = OCCUPIED
    map_file = write_map(directory, shades, name="two-rooms")
    fleet_file = directory / "fleet.yaml"
    fleet_file.write_text(
        f"""floor:
  map: {map_file.name}
  robot_radius: 0.2
robots:
  - thing: left
    spoken: [rover one, the left rover]
    start: {{x: 4.3, y: 0.8, theta: 0.0}}
  - thing: right
    spoken: [rover two, the right rover]
    start: {{x: 9.0, y: 4.0, theta: 3.1416}}
zones:
  - id: LOADING
    spoken: [loading zone, the loading zone]
    pose: {{x: 1.0, y: 4.0, theta: 3.1416}}
    radius: 0.3
  - id: A
    spoken: [zone a]
    pose: {{x: 6.0, y: 0.8, theta: 0.0}}
    radius: 0.3
  - id: B
    spoken: [zone b]
    pose: {{x: 1.0, y: 1.5, theta: 3.1416}}
    radius: 0.3
{sim_fleet_extra}"""
    )
    return TwoRooms(
        map_file=map_file,
        fleet_file=fleet_file,
        wall_left=WALL_X_M - WALL_HALF_M,
        wall_right=WALL_X_M + WALL_HALF_M,
        gap_bottom=GAP_BOTTOM_M,
    )


def warehouse_shades(columns: int, rows: int, *, resolution: float = RESOLUTION) -> np.ndarray:
    """A made-up warehouse, `columns` x `rows` cells: outer walls, then racks 1 m deep and 8 m
    long in rows 4 m apart, with 2.5 m cross aisles between them and clear bands 6 m wide
    along the west and east walls, where the zones are."""
    shades = np.full((rows, columns), FREE, dtype=np.uint8)
    wall = max(2, round(0.1 / resolution))
    shades[:wall, :] = shades[-wall:, :] = shades[:, :wall] = shades[:, -wall:] = OCCUPIED
    cell = 1.0 / resolution
    band, depth, length, pitch, cross = (round(m * cell) for m in (6.0, 1.0, 8.0, 4.0, 2.5))
    for top in range(band, rows - band - depth, pitch):
        for left in range(band, columns - band - length, length + cross):
            shades[top : top + depth, left : left + length] = OCCUPIED
    return shades


def warehouse(directory: Path, columns: int, rows: int, *, robots: int = 2) -> Path:
    """The warehouse map and a fleet of `robots` rovers on it (parked on its free ground by
    `vahr up`'s rule), zones LOADING on the west wall and A-D on the east one; the fleet
    file's path."""
    shades = warehouse_shades(columns, rows)
    map_file = write_map(directory, shades, name="warehouse")
    width, height = columns * RESOLUTION, rows * RESOLUTION
    zones = [("LOADING", "loading zone", 2.0, height / 2, 3.1416)]
    zones += [
        (letter, f"zone {letter.lower()}", width - 2.0, height * (4 - i - 0.5) / 4, 0.0)
        for i, letter in enumerate("ABCD")
    ]
    zone_lines = "".join(
        f"  - {{id: {zid}, spoken: [{name}], pose: {{x: {x:.2f}, y: {y:.2f}, theta: {t}}}, "
        f"radius: 0.4}}\n"
        for zid, name, x, y, t in zones
    )
    fleet = directory / "fleet.yaml"
    fleet.write_text(
        f"floor: {{map: {map_file.name}, robot_radius: 0.25}}\n"
        f"robots:\n  - {{thing: rover1, spoken: [rover one], start: {{x: 3.0, y: 3.0}}}}\n"
        f"zones:\n{zone_lines}"
    )
    if robots > 1:
        from vahr.domain import load_fleet
        from vahr.local.robots import fleet_of, write_fleet

        write_fleet(fleet_of(robots, load_fleet(fleet)), fleet)
    return fleet
