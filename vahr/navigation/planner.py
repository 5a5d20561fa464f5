"""Paths on a map: where a robot of a given radius may drive, and the shortest way there.

- **Where it may drive** (`Planner.drivable`): free cells whose centre is at least the
  robot's radius from the edge of every cell that is not free (occupied, unknown, off the
  map), by scipy's exact Euclidean distance transform; a closed zone's area (`keepout`) is
  kept out the same way, its edge grown by the radius.
- **One search from the goal** (`Planner.field`): scikit-image's `MCP_Geometric`, a
  Dijkstra search over the drivable cells with diagonal moves at their true length, run once
  from the goal, gives every cell's path length to it. A dispatcher reads 1,000 robots'
  costs from one field, a lookup each, and the same search's traceback is every robot's
  path there (`GoalField.route`).
- **Leaving a place it may not be** (a robot inside a zone that closed): the shortest way
  over free cells to the nearest drivable one, never through an occupied cell.
- **Straight where it can be**: the grid path is shortened by line of sight on the
  drivable cells (any-angle, as Theta* gives), so a robot drives few straight legs
  instead of a staircase of cells.

Fields are cached per goal cell; a planner for another set of closed areas is another
`Planner`, made by `FleetFloor.planner` (vahr/navigation/floor.py).
"""

from __future__ import annotations

import math
import threading
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from vahr.navigation.occupancy import OccupancyGrid

# A robot inside a cell it may not drive on looks this far (metres) for one it may, before
# looking over the whole map.
ESCAPE_WINDOW_M = 6.0
# How finely line of sight is sampled along a leg, in cells.
SIGHT_STEP_CELLS = 0.25


@dataclass(frozen=True)
class Route:
    """A planned path: map-frame points from the start to the goal, and its length (m)."""

    points: tuple[tuple[float, float], ...]
    length: float


class Planner:
    """Where a robot of `robot_radius` may drive on `grid` with `keepout` cells closed,
    and the paths between places (see the module docstring)."""

    def __init__(
        self, grid: OccupancyGrid, robot_radius: float, keepout: np.ndarray | None = None
    ) -> None:
        from scipy.ndimage import distance_transform_edt

        self.grid = grid
        self.robot_radius = robot_radius
        self.resolution = grid.resolution
        # Distance, in cells, from each cell's centre to the nearest centre of a cell that
        # is not free; off the map counts as not free (the padding).
        padded = np.pad(grid.free, 1, constant_values=False)
        to_obstacle = distance_transform_edt(padded)[1:-1, 1:-1]
        # The body must clear the obstacle cell's edge, half a cell nearer than its centre.
        reach = robot_radius / self.resolution + 0.5
        self.clearance = np.maximum(to_obstacle - 0.5, 0.0) * self.resolution
        drivable = to_obstacle >= reach
        if keepout is not None and keepout.any():
            to_keepout = distance_transform_edt(~keepout)
            drivable &= to_keepout >= reach
        self.drivable: np.ndarray = drivable
        self.keepout = keepout
        self._costs = np.where(drivable, 1.0, np.inf)
        self._fields: dict[tuple[int, int], GoalField] = {}
        self._lock = threading.Lock()

    # -- places ---------------------------------------------------------------------------

    def cell(self, x: float, y: float) -> tuple[int, int] | None:
        return self.grid.cell(x, y)

    def may_stand(self, x: float, y: float) -> bool:
        """Whether a robot may stand at the point (on a drivable cell)."""
        cell = self.grid.cell(x, y)
        return cell is not None and bool(self.drivable[cell])

    # -- searches -------------------------------------------------------------------------

    def field(self, x: float, y: float) -> GoalField:
        """Every cell's path length to the goal at (x, y): one search, cached per cell."""
        goal = self.grid.cell(x, y)
        if goal is None:
            return GoalField(self, None, (x, y))
        with self._lock:
            field = self._fields.get(goal)
            if field is None:
                field = self._fields[goal] = GoalField(self, goal, (x, y))
        return field

    def plan(self, start: tuple[float, float], goal: tuple[float, float]) -> Route | None:
        """The path from `start` to `goal`, None when there is none."""
        return self.field(*goal).route(*start, goal=goal)

    def escape(self, x: float, y: float) -> Route | None:
        """From a point a robot may not stand at, the shortest way over free cells (never an
        occupied one) to the nearest cell it may stand on; None when there is none."""
        from skimage.graph import MCP_Geometric

        start = self.grid.cell(x, y)
        if start is None:
            return None
        passable = self.grid.free
        window = max(1, round(ESCAPE_WINDOW_M / self.resolution))
        for reach in (window, max(self.grid.rows, self.grid.columns)):
            low_r, low_c = max(0, start[0] - reach), max(0, start[1] - reach)
            high_r = min(self.grid.rows, start[0] + reach + 1)
            high_c = min(self.grid.columns, start[1] + reach + 1)
            drivable = self.drivable[low_r:high_r, low_c:high_c]
            ends = np.argwhere(drivable)
            if not len(ends):
                continue
            costs = np.where(passable[low_r:high_r, low_c:high_c], 1.0, np.inf)
            local = (start[0] - low_r, start[1] - low_c)
            costs[local] = 1.0  # the robot is there, whatever the cell holds
            search = MCP_Geometric(costs, fully_connected=True)
            cumulative, _ = search.find_costs([local], [tuple(end) for end in ends])
            reached = cumulative[drivable]
            if not np.isfinite(reached).any():
                continue
            best = ends[int(np.argmin(np.where(np.isfinite(reached), reached, np.inf)))]
            cells = [(r + low_r, c + low_c) for r, c in search.traceback(tuple(best))]
            points = [(x, y), *(self.grid.centre(r, c) for r, c in cells[1:])]
            legs = _shortened(points, self._sight(passable, allow=start))
            return Route(tuple(legs), _length(legs))
        return None

    # -- line of sight ---------------------------------------------------------------------

    def _sight(self, allowed: np.ndarray, allow: tuple[int, int] | None = None) -> _Sight:
        return _Sight(self.grid, allowed, allow)


class GoalField:
    """Every drivable cell's path length (metres) to one goal, from one search.

    `distance(x, y)` is what a dispatcher ranks by; `route(x, y)` the path a robot drives.
    A point on no drivable cell is first led out by `Planner.escape`; math.inf and None
    mean there is no way.
    """

    def __init__(
        self, planner: Planner, goal: tuple[int, int] | None, point: tuple[float, float]
    ) -> None:
        self.planner = planner
        self.goal = goal
        self.point = point
        self._search = None
        self._metres: np.ndarray | None = None
        if goal is not None and planner.drivable[goal]:
            from skimage.graph import MCP_Geometric

            search = MCP_Geometric(planner._costs, fully_connected=True)
            cumulative, _ = search.find_costs([goal])
            self._search = search
            self._metres = cumulative * planner.resolution

    def metres(self) -> np.ndarray:
        """Every cell's path length to the goal (math.inf where none), row 0 at the bottom."""
        if self._metres is None:
            return np.full(self.planner.drivable.shape, np.inf)
        return self._metres

    @property
    def reachable(self) -> bool:
        """Whether the goal itself is a place a robot may stand (else nothing reaches it)."""
        return self._metres is not None

    def distance(self, x: float, y: float) -> float:
        """Metres along the path from (x, y) to the goal (grid moves, before shortening, so
        every robot is measured alike); math.inf when there is none."""
        metres = self._metres
        if metres is None:
            return math.inf
        grid = self.planner.grid
        column = math.floor((x - grid.origin_x) / grid.resolution)
        row = math.floor((y - grid.origin_y) / grid.resolution)
        if 0 <= row < grid.rows and 0 <= column < grid.columns:
            value = float(metres[row, column])
            if value != math.inf:
                return value
        out = self.planner.escape(x, y)
        if out is None:
            return math.inf
        end = out.points[-1]
        return out.length + self.distance(*end) if self.planner.may_stand(*end) else math.inf

    def distances(self, xs: list[float], ys: list[float]) -> list[float]:
        """`distance` of many points at once: one array lookup for those on drivable cells
        (every robot, as a rule), `distance` for the rest."""
        metres = self._metres
        if metres is None:
            return [math.inf] * len(xs)
        grid = self.planner.grid
        columns = np.floor((np.asarray(xs, dtype=float) - grid.origin_x) / grid.resolution)
        rows = np.floor((np.asarray(ys, dtype=float) - grid.origin_y) / grid.resolution)
        inside = (rows >= 0) & (rows < grid.rows) & (columns >= 0) & (columns < grid.columns)
        found = np.full(len(xs), math.inf)
        found[inside] = metres[rows[inside].astype(np.intp), columns[inside].astype(np.intp)]
        lengths: list[float] = found.tolist()
        for index in np.flatnonzero(~np.isfinite(found)).tolist():
            lengths[index] = self.distance(xs[index], ys[index])
        return lengths

    def route(self, x: float, y: float, *, goal: tuple[float, float] | None = None) -> Route | None:
        """The path a robot at (x, y) drives to the goal, ending at `goal` (default: the
        point the field was made for); None when there is none."""
        if self._metres is None or self._search is None:
            return None
        end = goal or self.point
        planner = self.planner
        cell = planner.grid.cell(x, y)
        lead: list[tuple[float, float]] = []
        if cell is None or not np.isfinite(self._metres[cell]):
            out = planner.escape(x, y)
            if out is None:
                return None
            lead = list(out.points[:-1])
            x, y = out.points[-1]
            cell = planner.grid.cell(x, y)
            if cell is None or not np.isfinite(self._metres[cell]):
                return None
        cells = self._search.traceback(cell)  # from the goal to the robot's cell
        points = [(x, y), *(planner.grid.centre(r, c) for r, c in reversed(cells[1:-1]))]
        points.append(end)
        legs = lead + _shortened(points, planner._sight(planner.drivable))
        return Route(tuple(legs), _length(legs))


class _Sight:
    """Whether a straight leg between two points crosses only `allowed` cells."""

    def __init__(
        self, grid: OccupancyGrid, allowed: np.ndarray, allow: tuple[int, int] | None
    ) -> None:
        self.grid = grid
        self.allowed = allowed
        self.allow = allow

    def clear(self, start: tuple[float, float], end: tuple[float, float]) -> bool:
        grid = self.grid
        span = math.hypot(end[0] - start[0], end[1] - start[1]) / grid.resolution
        samples = max(2, math.ceil(span / SIGHT_STEP_CELLS) + 1)
        along = np.linspace(0.0, 1.0, samples)
        xs = start[0] + (end[0] - start[0]) * along
        ys = start[1] + (end[1] - start[1]) * along
        columns = np.floor((xs - grid.origin_x) / grid.resolution).astype(np.int64)
        rows = np.floor((ys - grid.origin_y) / grid.resolution).astype(np.int64)
        if rows.min() < 0 or columns.min() < 0:
            return False
        if rows.max() >= grid.rows or columns.max() >= grid.columns:
            return False
        passes = self.allowed[rows, columns]
        if self.allow is not None:
            passes |= (rows == self.allow[0]) & (columns == self.allow[1])
        return bool(passes.all())


def _shortened(points: list[tuple[float, float]], sight: _Sight) -> list[tuple[float, float]]:
    """The path through `points` with every corner that line of sight can skip left out:
    from each kept point, the farthest later point in sight (found by halving, as a grid
    path's points come into and out of sight in order), then on from there."""
    if len(points) <= 2:
        return list(points)
    kept = [points[0]]
    here = 0
    last = len(points) - 1
    while here < last:
        low, high = here + 1, last
        while low < high:
            middle = (low + high + 1) // 2
            if sight.clear(points[here], points[middle]):
                low = middle
            else:
                high = middle - 1
        here = low
        kept.append(points[here])
    return kept


def _length(points: list[tuple[float, float]]) -> float:
    return sum(
        math.hypot(b[0] - a[0], b[1] - a[1]) for a, b in zip(points, points[1:], strict=False)
    )
