"""The distance fields the dispatcher Lambda ranks by, written when the bundle is built.

`write_distances(fleet, path)` runs the one search per zone on the fleet's map (every zone
open, `vahr.navigation`) and writes what `vahr.dispatch.grid_routes` reads in the Lambda,
which carries no numpy: a JSON header line, then each zone's field as little-endian 16-bit
path lengths, zlib-compressed (that module says the format). `infra/lambda_asset.py` calls
it for a fleet whose floor is a map.
"""

from __future__ import annotations

import json
import math
import zlib
from typing import TYPE_CHECKING

import numpy as np

from vahr.dispatch.grid_routes import FORMAT, MAX_SIDE, NO_PATH, fleet_key
from vahr.errors import VahrError
from vahr.navigation import load_floor

if TYPE_CHECKING:
    from pathlib import Path

    from vahr.domain.fleet import Fleet

# Path lengths are kept in centimetres while the longest fits 16 bits, else coarser.
UNITS_M = (0.01, 0.02, 0.05, 0.1, 0.2, 0.5, 1.0)


def write_distances(fleet: Fleet, path: Path) -> int:
    """Write the distances of `fleet` (on a map) to `path`; the bytes written."""
    floor = load_floor(fleet)
    if floor is None:
        raise VahrError("the fleet's floor is not a map: it needs no distances")
    grid = floor.grid
    step = max(1, math.ceil(max(grid.rows, grid.columns) / MAX_SIDE))
    rows, columns = math.ceil(grid.rows / step), math.ceil(grid.columns / step)
    fields: dict[str, np.ndarray] = {}
    longest = 0.0
    for zone in fleet.zones:
        metres = floor.open.field(zone.pose.x, zone.pose.y).metres()
        # A coarse cell holds the shortest path length of the map cells in it.
        padded = np.full((rows * step, columns * step), np.inf)
        padded[: grid.rows, : grid.columns] = metres
        coarse = padded.reshape(rows, step, columns, step).min(axis=(1, 3))
        fields[zone.id] = coarse
        finite = coarse[np.isfinite(coarse)]
        longest = max(longest, float(finite.max()) if finite.size else 0.0)
    unit = next((u for u in UNITS_M if longest / u < NO_PATH), UNITS_M[-1])
    blobs: list[bytes] = []
    where: dict[str, list[int]] = {}
    offset = 0
    for zone_id, coarse in fields.items():
        values = np.where(np.isfinite(coarse), np.rint(coarse / unit), NO_PATH)
        blob = zlib.compress(values.astype("<u2").tobytes(), 9)
        where[zone_id] = [offset, len(blob)]
        blobs.append(blob)
        offset += len(blob)
    header = {
        "format": FORMAT,
        "fleet": fleet_key(fleet),
        "origin": [grid.origin_x, grid.origin_y],
        "cell_m": grid.resolution * step,
        "rows": rows,
        "columns": columns,
        "unit_m": unit,
        "fields": where,
    }
    data = json.dumps(header).encode() + b"\n" + b"".join(blobs)
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_bytes(data)
    return len(data)
