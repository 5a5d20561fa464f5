"""Everything a handler needs, built once at cold start: config, fleet, names, robots."""

from __future__ import annotations

import random
from typing import TYPE_CHECKING

import msgspec

from skill import fleet_source
from skill.fleet_acknowledgment import FleetAcknowledgments
from skill.robots import Robots
from skill.vocabulary import Vocabulary

if TYPE_CHECKING:
    from skill.config import SkillConfig
    from skill.gateway import RobotGateway
    from vahr.domain import Fleet


class SkillRuntime(msgspec.Struct, frozen=True):
    """The skill's long-lived collaborators, shared by every request of a Lambda instance."""

    config: SkillConfig
    fleet: Fleet
    vocabulary: Vocabulary
    gateway: RobotGateway
    robots: Robots
    rng: random.Random

    @classmethod
    def create(
        cls, config: SkillConfig, gateway: RobotGateway, *, fleet: Fleet | None = None
    ) -> SkillRuntime:
        fleet = fleet or fleet_source.load(config.fleet_file)
        return cls(
            config=config,
            fleet=fleet,
            vocabulary=Vocabulary(fleet),
            gateway=gateway,
            robots=Robots(
                gateway, config.ack_timeout_s, many=FleetAcknowledgments.for_config(config)
            ),
            rng=random.Random(),
        )
