"""What the questions about the whole fleet share (where the robots are, which are in
trouble, their batteries): a small fleet is read shadow by shadow, a large one is asked of
the fleet index, whose client is made on first use (a two-robot skill never needs it)."""

from __future__ import annotations

from typing import TYPE_CHECKING

from skill import fleet_status
from skill.errors import GatewayError
from skill.iot_fleet_index import IotFleetIndex

if TYPE_CHECKING:
    from skill.fleet_status import FleetState
    from skill.iot_fleet_index import FleetIndex
    from skill.robots import ShadowRead
    from skill.runtime import SkillRuntime

# The most robots whose shadows a question reads one by one. Past it the reads cost more
# than the index's few calls (each read is a billable GetThingShadow, and 25 of them take
# as long as the whole answer may), and one sentence per robot would pass the word bound
# anyway: a robot's sentence is 4 to 15 words.
SHADOW_READ_MAX = 25


class FleetQuestion:
    """A handler's access to the fleet's shadows or its index."""

    def __init__(self, runtime: SkillRuntime, fleet_index: FleetIndex | None = None) -> None:
        self.runtime = runtime
        self._index = fleet_index

    @property
    def index(self) -> FleetIndex:
        if self._index is None:
            self._index = IotFleetIndex.from_config(self.runtime.config)
        return self._index

    def read_all(self) -> list[ShadowRead] | None:
        """Every robot's shadow, for a small fleet (None for a large one)."""
        things = list(self.runtime.fleet.robot_things)
        if len(things) > SHADOW_READ_MAX:
            return None
        reads = self.runtime.robots.shadows(things)
        if all(read.error is not None for read in reads.values()):
            # Nothing could be read at all: that is an outage, not a robot's state.
            raise GatewayError("; ".join(str(read.error) for read in reads.values()))
        return list(reads.values())

    def state(self, reads: list[ShadowRead] | None) -> FleetState:
        if reads is not None:
            return fleet_status.from_shadows(reads)
        return fleet_status.from_index(self.index, len(self.runtime.fleet.robots))
