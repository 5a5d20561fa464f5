"""Everything a handler needs, built once at cold start: config, fleet, names, robots, who
may do what, and the audit trail."""

from __future__ import annotations

import random
from typing import TYPE_CHECKING

import msgspec

from skill import fleet_source
from skill.fleet_acknowledgment import FleetAcknowledgments
from skill.robots import Robots
from skill.speakers import people_directory
from skill.trail import audit_trail
from skill.vocabulary import Vocabulary
from vahr.domain.people import confirmation_on

if TYPE_CHECKING:
    from skill.config import SkillConfig
    from skill.gateway import RobotGateway
    from skill.speakers import PeopleDirectory
    from skill.trail import Trail
    from vahr.domain import Fleet


class SkillRuntime(msgspec.Struct, frozen=True):
    """The skill's long-lived collaborators, shared by every request of a Lambda instance."""

    config: SkillConfig
    fleet: Fleet
    vocabulary: Vocabulary
    gateway: RobotGateway
    robots: Robots
    rng: random.Random
    people: PeopleDirectory
    trail: Trail
    # Fleet-wide commands are confirmed first (skill.guard): as VAHR_CONFIRM says, else as
    # the fleet file says, else whenever people are known.
    confirmation: bool
    group_threshold: int

    @classmethod
    def create(
        cls, config: SkillConfig, gateway: RobotGateway, *, fleet: Fleet | None = None
    ) -> SkillRuntime:
        fleet = fleet or fleet_source.load(config.fleet_file)
        rules = fleet.confirmation_rules
        return cls(
            config=config,
            fleet=fleet,
            vocabulary=Vocabulary(fleet),
            gateway=gateway,
            robots=Robots(
                gateway, config.ack_timeout_s, many=FleetAcknowledgments.for_config(config)
            ),
            rng=random.Random(),
            people=people_directory(config),
            trail=audit_trail(config),
            confirmation=confirmation_on(config.confirm, rules.enabled, config.people_known),
            group_threshold=rules.group_threshold,
        )
