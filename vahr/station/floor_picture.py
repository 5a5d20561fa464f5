"""The map a fleet's floor names, as the station's page draws it.

`floor_map(fleet)` reads the map (`vahr.navigation.load_floor`) once and gives what the
page needs: the picture as a PNG (occupied cells dark, free ones light, unknown ones
transparent, one pixel a cell, drawn at the map's scale under the robots), where it lies,
and the part of it that is not unknown, which the page zooms to (a SLAM map is mostly
unknown space around the rooms mapped). A fleet without a map has none.
"""

from __future__ import annotations

import io
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from vahr.domain.fleet import Point
from vahr.navigation import load_floor
from vahr.station.page_messages import FloorMap, MapExtent

if TYPE_CHECKING:
    from vahr.domain import Fleet

# Where the page fetches the picture.
MAP_PATH = "/api/map.png"
# Colours of the picture (RGBA): walls and obstacles, free space; unknown is transparent.
OCCUPIED = (52, 58, 64, 255)
FREE = (250, 250, 247, 255)


@dataclass(frozen=True)
class FloorPicture:
    """The map as the page gets it: where it lies (`view`) and the PNG (`png`)."""

    view: FloorMap
    png: bytes


def floor_picture(fleet: Fleet) -> FloorPicture | None:
    """The picture of the fleet's map, or None for a drawn floor."""
    floor = load_floor(fleet)
    if floor is None:
        return None
    from PIL import Image

    grid = floor.grid
    pixels = np.zeros((grid.rows, grid.columns, 4), dtype=np.uint8)
    pixels[grid.free] = FREE
    pixels[grid.occupied] = OCCUPIED
    # The picture's first row is the map's top; the grid keeps its bottom row first.
    picture = Image.fromarray(np.ascontiguousarray(np.flipud(pixels)), "RGBA")
    encoded = io.BytesIO()
    picture.save(encoded, format="PNG", optimize=True)
    known = grid.free | grid.occupied
    rows, columns = np.nonzero(known)
    if rows.size:
        left = grid.origin_x + columns.min() * grid.resolution
        right = grid.origin_x + (columns.max() + 1) * grid.resolution
        bottom = grid.origin_y + rows.min() * grid.resolution
        top = grid.origin_y + (rows.max() + 1) * grid.resolution
    else:
        left, bottom = grid.origin_x, grid.origin_y
        right, top = left + grid.width, bottom + grid.height
    view = FloorMap(
        image=MAP_PATH,
        origin=Point(grid.origin_x, grid.origin_y),
        resolution=grid.resolution,
        columns=grid.columns,
        rows=grid.rows,
        known=MapExtent(
            left=round(float(left), 3),
            bottom=round(float(bottom), 3),
            right=round(float(right), 3),
            top=round(float(top), 3),
        ),
    )
    return FloorPicture(view=view, png=encoded.getvalue())
