"""Path lengths on a map without numpy: the distance fields `vahr.navigation` wrote, read.

The dispatcher Lambda ranks robots by their planned path length like the local host, but
its bundle carries no numpy, SciPy or scikit-image (the bundle's size and cold start). So
the bundle build (`infra/lambda_asset.py`) runs the one search per zone ahead of time
(`vahr.navigation.distances.write_distances`) and ships the result, one small file: a JSON
header line, then each zone's field as 16-bit path lengths (`unit_m` metres each, 65535 for
"no path"), row by row from the map's bottom, zlib-compressed. A field of a large map is
kept on a coarser grid (`step` map cells a side, the shortest length in the block), at most
`MAX_SIDE` cells a side. A lookup is one index into an `array`.

The fields are those of the map with every zone open: on AWS a closed zone is never sent to
and its robots leave it, but the ranking does not lengthen paths that would pass through
a closed zone's area (the local host does).
"""

from __future__ import annotations

import array
import hashlib
import json
import math
import os
import sys
import zlib
from typing import TYPE_CHECKING

from vahr.dispatch.ranking import STRAIGHT
from vahr.domain.fleet import DEFAULT_FLEET_FILE

if TYPE_CHECKING:
    from vahr.dispatch.ranking import Routes
    from vahr.domain.fleet import Fleet, Zone

FORMAT = "vahr-distances/1"
# Where the bundle build writes the distances of the bundled fleet: beside its fleet.yaml.
BUNDLED_FILE = os.path.join(os.path.dirname(DEFAULT_FLEET_FILE), "fleet-distances.bin")  # noqa: PTH118, PTH120
# The value that means "no path leads there".
NO_PATH = 65535
# A field's grid is at most this many cells a side (coarser cells beyond).
MAX_SIDE = 512


class DistancesError(ValueError):
    """A distances file that cannot serve this fleet (missing, stale, unreadable)."""


def fleet_key(fleet: Fleet) -> str:
    """What the distances depend on in the fleet: its zones' poses and the robots' radius
    (and the map, by name; the bundle is built from the map file itself)."""
    floor = fleet.floor
    radius = floor.robot_radius if floor is not None else None
    name = (floor.map or "").replace("\\", "/").rsplit("/", 1)[-1] if floor is not None else ""
    parts = [name, radius, [(zone.id, zone.pose.x, zone.pose.y) for zone in fleet.zones]]
    return hashlib.sha256(json.dumps(parts).encode()).hexdigest()[:32]


class GridField:
    """One zone's path lengths, looked up by point."""

    def __init__(self, routes: GridRoutes, values: array.array[int]) -> None:
        self._values = values
        self._routes = routes

    def distance(self, x: float, y: float) -> float:
        grid = self._routes
        column = math.floor((x - grid.origin_x) / grid.cell_m)
        row = math.floor((y - grid.origin_y) / grid.cell_m)
        if not (0 <= row < grid.rows and 0 <= column < grid.columns):
            return math.inf
        value = self._values[row * grid.columns + column]
        return math.inf if value == NO_PATH else value * grid.unit_m

    def distances(self, xs: list[float], ys: list[float]) -> list[float]:
        """`distance` of many points: what `rank` asks of 1,000 robots at once."""
        grid, values, floor, inf = self._routes, self._values, math.floor, math.inf
        left, bottom, cell = grid.origin_x, grid.origin_y, grid.cell_m
        rows, columns, unit = grid.rows, grid.columns, grid.unit_m
        lengths = []
        for x, y in zip(xs, ys, strict=True):
            column, row = floor((x - left) / cell), floor((y - bottom) / cell)
            if 0 <= row < rows and 0 <= column < columns:
                value = values[row * columns + column]
                lengths.append(inf if value == NO_PATH else value * unit)
            else:
                lengths.append(inf)
        return lengths


class GridRoutes:
    """`vahr.dispatch.Routes` from a distances file (see the module docstring)."""

    def __init__(self, header: dict[str, object], fields: dict[str, array.array[int]]) -> None:
        self.origin_x, self.origin_y = (float(value) for value in header["origin"])  # type: ignore[attr-defined]
        self.cell_m = float(header["cell_m"])  # type: ignore[arg-type]
        self.rows = int(header["rows"])  # type: ignore[call-overload]
        self.columns = int(header["columns"])  # type: ignore[call-overload]
        self.unit_m = float(header["unit_m"])  # type: ignore[arg-type]
        self._fields = {zone: GridField(self, values) for zone, values in fields.items()}

    def field(self, zone: Zone) -> GridField:
        return self._fields[zone.id]

    @classmethod
    def read(cls, path: str, fleet: Fleet) -> GridRoutes:
        """The distances in `path` for `fleet`; DistancesError when they are not for it."""
        try:
            with open(path, "rb") as stream:  # noqa: PTH123 - on the Lambda's cold start
                data = stream.read()
        except OSError as err:
            raise DistancesError(f"cannot read {path}: {err.strerror}") from err
        line, _, body = data.partition(b"\n")
        try:
            header = json.loads(line)
        except ValueError as err:
            raise DistancesError(f"{path} is not a distances file") from err
        if not isinstance(header, dict) or header.get("format") != FORMAT:
            raise DistancesError(f"{path} is not a {FORMAT} file")
        if header.get("fleet") != fleet_key(fleet):
            raise DistancesError(
                f"{path} was made for another fleet or map; build the bundle again"
            )
        fields: dict[str, array.array[int]] = {}
        size = int(header["rows"]) * int(header["columns"])
        for zone in fleet.zones:
            where = header["fields"].get(zone.id)
            if where is None:
                raise DistancesError(f"{path} holds no distances to zone {zone.id}")
            start, length = where
            values = array.array("H")
            values.frombytes(zlib.decompress(body[start : start + length]))
            if sys.byteorder != "little":
                values.byteswap()
            if len(values) != size:
                raise DistancesError(f"{path}: the field of zone {zone.id} is cut short")
            fields[zone.id] = values
        return cls(header, fields)


def floor_routes(fleet: Fleet, path: str = BUNDLED_FILE) -> Routes:
    """The dispatcher's routes for `fleet`: straight lines on a drawn floor, the distances
    file `path` on a map (DistancesError when it is missing or not for this fleet)."""
    if fleet.floor is None or fleet.floor.map is None:
        return STRAIGHT
    return GridRoutes.read(path, fleet)
