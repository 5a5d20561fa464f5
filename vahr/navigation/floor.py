"""A fleet on its map: the map read, the fleet checked against it, planners per set of
closed zones, and the floor as the station draws it.

`load_floor(fleet)` is the one place that reads `floor.map` (every host that plans or
draws calls it: `vahr up`, the robots, the station, the dispatcher), and it refuses a fleet
whose robots or zones cannot be on the map in one line naming the entry: a start or zone
off the map, in a wall, in unknown space, too near a wall for the robot's radius, or where
no path leads from the first robot's start.
"""

from __future__ import annotations

import threading
from typing import TYPE_CHECKING

import msgspec
import numpy as np

from vahr.domain.fleet import Floor, Point
from vahr.navigation.occupancy import MapError, load_map
from vahr.navigation.planner import GoalField, Planner

if TYPE_CHECKING:
    from collections.abc import Iterable

    from vahr.domain.fleet import Fleet, Pose, Zone
    from vahr.navigation.occupancy import OccupancyGrid


class FleetFloor:
    """The fleet's map with its planners: one for every set of closed zones asked for."""

    def __init__(self, fleet: Fleet, grid: OccupancyGrid) -> None:
        assert fleet.floor is not None
        self.fleet = fleet
        self.grid = grid
        self.robot_radius = fleet.floor.robot_radius
        self._planners: dict[frozenset[str], Planner] = {}
        self._lock = threading.Lock()
        self.open = self.planner(frozenset())

    # -- planners ---------------------------------------------------------------------------

    def planner(self, closed: Iterable[str] = ()) -> Planner:
        """The planner with the areas of the `closed` zones kept out (zones without an
        area close no ground: robots still drive past them)."""
        areas = frozenset(
            zone.id for zone in self.fleet.zones if zone.id in set(closed) and zone.area
        )
        with self._lock:
            planner = self._planners.get(areas)
            if planner is None:
                keepout = self.keepout(areas) if areas else None
                planner = Planner(self.grid, self.robot_radius, keepout)
                self._planners[areas] = planner
        return planner

    def leaving(self, zone_id: str, closed: Iterable[str] = ()) -> Planner:
        """The planner a robot leaving `zone_id` plans with: the closed zones' areas and
        the zone itself (its area, or its arrival circle when it has none) kept out."""
        zone = self.fleet.zone(zone_id)
        if zone.area:
            return self.planner({*closed, zone_id})
        key = frozenset(z.id for z in self.fleet.zones if z.id in set(closed) and z.area) | {
            f"circle:{zone_id}"
        }
        with self._lock:
            planner = self._planners.get(key)
        if planner is None:
            mask = self.keepout(key - {f"circle:{zone_id}"})
            grid = self.grid
            rows, columns = np.indices(mask.shape)
            xs = grid.origin_x + (columns + 0.5) * grid.resolution
            ys = grid.origin_y + (rows + 0.5) * grid.resolution
            mask |= np.hypot(xs - zone.pose.x, ys - zone.pose.y) <= zone.radius
            planner = Planner(grid, self.robot_radius, mask)
            with self._lock:
                self._planners[key] = planner
        return planner

    def keepout(self, zone_ids: Iterable[str]) -> np.ndarray:
        """The cells inside the areas of these zones."""
        from skimage.draw import polygon

        mask = np.zeros(self.grid.free.shape, dtype=bool)
        for zone_id in zone_ids:
            area = self.fleet.zone(zone_id).area
            if not area:
                continue
            grid = self.grid
            rows = [(point.y - grid.origin_y) / grid.resolution - 0.5 for point in area]
            columns = [(point.x - grid.origin_x) / grid.resolution - 0.5 for point in area]
            inside_rows, inside_columns = polygon(rows, columns, shape=mask.shape)
            mask[inside_rows, inside_columns] = True
        return mask

    def inside(self, zone: Zone, point: Pose | Point) -> bool:
        """Whether the point is in the zone: in its area when it has one, else within its
        arrival radius."""
        if zone.area:
            from skimage.measure import points_in_poly

            corners = np.array([(corner.x, corner.y) for corner in zone.area])
            return bool(points_in_poly(np.array([(point.x, point.y)]), corners)[0])
        return zone.pose.distance_to(_pose(point)) <= zone.radius

    # -- the fleet on it ----------------------------------------------------------------------

    def check(self) -> FleetFloor:
        """Every robot's start and every zone is a place a robot may stand, and a path leads
        from the first robot's start to each; MapError naming the first that is not."""
        from scipy.ndimage import label

        grid, planner = self.grid, self.open
        places = [
            (f"robots.{i}.start", robot.start, "the robot cannot start there")
            for i, robot in enumerate(self.fleet.robots)
        ]
        places += [
            (f"zones.{i}.pose", zone.pose, "no robot can reach it")
            for i, zone in enumerate(self.fleet.zones)
        ]
        for field, pose, consequence in places:
            at = f"({pose.x:g}, {pose.y:g})"
            cell = grid.cell(pose.x, pose.y)
            if cell is None:
                raise MapError(
                    f"{field}: {at} is off the map {grid.source.name} ({grid.extent()}), "
                    f"so {consequence}"
                )
            if grid.occupied[cell]:
                raise MapError(
                    f"{field}: {at} is inside a wall on the map {grid.source.name}, "
                    f"so {consequence}"
                )
            if not grid.free[cell]:
                raise MapError(
                    f"{field}: {at} is in unknown space on the map {grid.source.name}, "
                    f"so {consequence}"
                )
            if not planner.drivable[cell]:
                raise MapError(
                    f"{field}: {at} is {planner.clearance[cell]:.2f} m from a wall; a robot "
                    f"needs {self.robot_radius:g} m (floor.robot_radius), so {consequence}"
                )
        regions, _ = label(planner.drivable, structure=np.ones((3, 3), dtype=bool))
        first_field, first, _ = places[0]
        home = regions[grid.cell(first.x, first.y)]
        for field, pose, _consequence in places[1:]:
            if regions[grid.cell(pose.x, pose.y)] != home:
                raise MapError(
                    f"{field}: ({pose.x:g}, {pose.y:g}) cannot be reached from {first_field} "
                    f"on the map {grid.source.name} (no path a robot of radius "
                    f"{self.robot_radius:g} m fits through)"
                )
        for index, zone in enumerate(self.fleet.zones):
            for corner, point in enumerate(zone.area or []):
                if grid.cell(point.x, point.y) is None:
                    raise MapError(
                        f"zones.{index}.area.{corner}: ({point.x:g}, {point.y:g}) is off the "
                        f"map {grid.source.name} ({grid.extent()})"
                    )
            if zone.area and not self.inside(zone, zone.pose):
                raise MapError(f"zones.{index}.area: does not hold the zone's own pose")
        return self

    def routes(self, closed: frozenset[str] = frozenset()) -> PlannedRoutes:
        """Path lengths for the dispatcher (`vahr.dispatch.Routes`) with `closed` zones'
        areas kept out: one search per zone, cached by the planner."""
        return PlannedRoutes(self.planner(closed))

    def parking(
        self, count: int, *, spacing: float, clear_of_zones: float, avoid: Iterable[Pose] = ()
    ) -> list[Pose]:
        """`count` places robots may start at, on a square lattice `spacing` apart over the
        drivable cells reachable from the first robot's start, each at least
        `clear_of_zones` metres from every zone and `spacing` from every pose in `avoid`;
        MapError when the map holds fewer."""
        from scipy.ndimage import label

        from vahr.domain.fleet import Pose

        grid, drivable = self.grid, self.open.drivable
        regions, _ = label(drivable, structure=np.ones((3, 3), dtype=bool))
        home_at = self.fleet.robots[0].start
        home = regions[grid.cell(home_at.x, home_at.y)]
        step = max(1, round(spacing / grid.resolution))
        rows, columns = np.mgrid[step // 2 : grid.rows : step, step // 2 : grid.columns : step]
        rows, columns = rows.ravel(), columns.ravel()
        usable = regions[rows, columns] == home
        xs = grid.origin_x + (columns + 0.5) * grid.resolution
        ys = grid.origin_y + (rows + 0.5) * grid.resolution
        for zone in self.fleet.zones:
            usable &= np.hypot(xs - zone.pose.x, ys - zone.pose.y) >= clear_of_zones
        for pose in avoid:
            usable &= np.hypot(xs - pose.x, ys - pose.y) >= spacing
        spots = [
            Pose(round(float(x), 3), round(float(y), 3))
            for x, y in zip(xs[usable], ys[usable], strict=True)
        ]
        if len(spots) < count:
            raise MapError(
                f"the map {grid.source.name} has room for {len(spots)} robots {spacing:g} m "
                f"apart and {clear_of_zones:g} m from the zones, not {count}"
            )
        return spots[:count]

    def drawn(self) -> Floor:
        """The fleet's floor with the map's size and origin filled in (what the station and
        `Fleet.layout` draw)."""
        floor = self.fleet.floor
        assert floor is not None
        return msgspec.structs.replace(
            floor,
            width=round(self.grid.width, 6),
            height=round(self.grid.height, 6),
            origin=Point(self.grid.origin_x, self.grid.origin_y),
        )

    def fleet_drawn(self) -> Fleet:
        """The fleet with `drawn()` as its floor."""
        return msgspec.structs.replace(self.fleet, floor=self.drawn())


class PlannedRoutes:
    """`vahr.dispatch.Routes` on a map: each zone's distance field from one search."""

    def __init__(self, planner: Planner) -> None:
        self.planner = planner

    def field(self, zone: Zone) -> GoalField:
        return self.planner.field(zone.pose.x, zone.pose.y)


def load_floor(fleet: Fleet) -> FleetFloor | None:
    """The fleet's map, read and checked; None for a fleet without one (a drawn floor)."""
    if fleet.floor is None or fleet.floor.map is None:
        return None
    _cached: dict[str, FleetFloor] = _FLOORS
    key = _key(fleet)
    with _FLOORS_LOCK:
        floor = _cached.get(key)
    if floor is not None:
        return floor
    grid = load_map(fleet.floor.map)
    floor = FleetFloor(fleet, grid).check()
    with _FLOORS_LOCK:
        _cached[key] = floor
    return floor


# One process often asks for the same fleet's floor from several parts (a swarm's robots,
# the station and the dispatcher in `vahr up`): it is read and checked once.
_FLOORS: dict[str, FleetFloor] = {}
_FLOORS_LOCK = threading.Lock()


def _key(fleet: Fleet) -> str:
    return msgspec.json.encode(fleet).decode()


def _pose(point: Pose | Point) -> Pose:
    from vahr.domain.fleet import Pose

    return point if isinstance(point, Pose) else Pose(point.x, point.y)
