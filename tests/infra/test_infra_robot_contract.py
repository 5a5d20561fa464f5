"""The robot agent, as built, stays inside the IoT policy the stack gives it.

The real `RobotAgent` (simulator backend, fast clock) runs a fleet command, a delivery and
a stop behind a link that records every subscription and publish (with its retain flag);
each must be allowed for placebot1 by the synthesized `vahr-robot-policy`. On AWS a denied
publish or subscription would silently cut the robot off, so this is checked here.
"""

from __future__ import annotations

import asyncio
from typing import TYPE_CHECKING, Any

import pytest
from aws_cdk.assertions import Template
from iot_policy_eval import Connection, IotPolicy
from template_tools import bare_stack, only

from infra.constructs.robot_policy import RobotPolicy
from robot_agent.agent import RobotAgent
from robot_agent.assembly import build_link
from robot_agent.backends.sim import SimBackend
from robot_agent.clock import ScaledClock
from robot_agent.config import AgentConfig, SimSettings
from robot_agent.core.recent_ids import RecentIds
from vahr.protocol import encode, new_command, topics

if TYPE_CHECKING:
    from collections.abc import Callable

    from vahr.domain import Fleet

THING = "placebot1"


class RecordingLink:
    """A `Link` that records what the agent subscribes to and publishes."""

    def __init__(self) -> None:
        self.routes: dict[str, Callable[[str, bytes], None]] = {}
        self.published: list[tuple[str, bool]] = []
        self.connected: list[Callable[[bool], None]] = []

    def publish(self, topic: str, payload: bytes, *, retain: bool = False) -> None:
        self.published.append((topic, retain))

    def add_route(self, topic_filter: str, handler: Callable[[str, bytes], None]) -> None:
        self.routes[topic_filter] = handler

    def on_connected(self, callback: Callable[[bool], None]) -> None:
        self.connected.append(callback)

    def on_disconnected(self, callback: Callable[[str], None]) -> None:
        pass


@pytest.fixture(scope="module")
def policy(tmp_path_factory: pytest.TempPathFactory) -> IotPolicy:
    stack = bare_stack(tmp_path_factory.mktemp("contract"))
    RobotPolicy(stack, "RobotPolicy", policy_name="vahr-robot-policy")
    document: dict[str, Any] = only(Template.from_stack(stack).to_json(), "AWS::IoT::Policy")[
        "PolicyDocument"
    ]
    return IotPolicy(document, Connection(THING))


async def drive_the_agent(fleet: Fleet) -> RecordingLink:
    clock = ScaledClock(speed_factor=200)
    link = RecordingLink()
    agent = RobotAgent(
        thing=THING, fleet=fleet, link=link, clock=clock, recent_ids=RecentIds(),
        backend=SimBackend(start=fleet.robot(THING).start, clock=clock, settings=SimSettings()),
    )  # fmt: skip
    agent.attach()
    for callback in link.connected:
        callback(False)
    commands = [
        (topics.FLEET_CMD, new_command("navigate", {"zone": "A"}, source="alexa")),
        (topics.robot_cmd(THING), new_command("deliver", {"zone": "B"}, source="alexa")),
    ]
    for topic, command in commands:
        link.routes[topic](topic, encode(command))
        await asyncio.wait_for(agent.executor.wait_idle(), timeout=30)
    stop = new_command("stop", {}, source="console")
    link.routes[topics.robot_cmd(THING)](topics.robot_cmd(THING), encode(stop))
    await asyncio.wait_for(agent.executor.wait_idle(), timeout=30)
    await asyncio.wait_for(agent.shut_down(), timeout=30)
    return link


def test_everything_the_agent_subscribes_to_and_publishes_is_allowed(
    policy: IotPolicy, fleet: Fleet
) -> None:
    # Given the agent run through a fleet command, a delivery and a stop
    link = asyncio.run(drive_the_agent(fleet))
    # Then it listened to its commands, the fleet, its peers and its shadow's answers
    assert {
        topics.robot_cmd(THING),
        topics.FLEET_CMD,
        topics.shadow(THING, "update/rejected"),
    } <= set(link.routes)
    # And the policy allows every subscription and the delivery of messages on it
    for topic_filter in link.routes:
        assert policy.can_subscribe(topic_filter), topic_filter
    # And every publish, retained ones included (presence, the `delivered` event)
    assert any(retain for _, retain in link.published)
    for topic, retain in sorted(set(link.published)):
        assert policy.can_publish(topic, retain=retain), (topic, retain)


def test_the_agents_client_id_and_last_will_are_allowed(policy: IotPolicy) -> None:
    # Given the link settings the agent builds (the same for AWS and a local broker)
    config = AgentConfig(thing=THING, broker="mqtt://127.0.0.1:1883")
    loop = asyncio.new_event_loop()
    try:
        settings = build_link(config, loop, ScaledClock()).settings
    finally:
        loop.close()
    # Then it connects as its own thing, and its retained last will is its own presence
    assert settings.client_id == THING
    assert policy.can_connect(settings.client_id)
    assert settings.will is not None
    assert settings.will.topic == topics.robot_presence(THING) and settings.will.retain
    assert policy.can_publish(settings.will.topic, retain=settings.will.retain)
