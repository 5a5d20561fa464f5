"""Navigation on a map: the ROS map a fleet's floor names, where robots may drive on it,
and their paths (docs/floors.md).

- `occupancy`: map_server's YAML and image read into an `OccupancyGrid` (`load_map`,
  `MapError`);
- `planner`: the drivable cells for a robot's radius, one search from a goal for every
  robot (`Planner.field`, `GoalField`), paths shortened by line of sight (`Route`);
- `floor`: the fleet checked against its map, planners per set of closed zones, the floor
  the station draws (`load_floor`, `FleetFloor`).

It imports the domain and numpy, SciPy, scikit-image and Pillow (lazily, where a map is
read or searched); the robots' simulator, the local dispatcher and the station use it. The
dispatcher Lambda does not: it reads the distances this package wrote for it
(`vahr.dispatch.grid_routes`).
"""

from __future__ import annotations

from vahr.navigation.floor import FleetFloor, load_floor
from vahr.navigation.occupancy import MapError, OccupancyGrid, load_map
from vahr.navigation.planner import GoalField, Planner, Route

__all__ = [
    "FleetFloor",
    "GoalField",
    "MapError",
    "OccupancyGrid",
    "Planner",
    "Route",
    "load_floor",
    "load_map",
]
