"""Build the parts of one robot from its configuration: clock, backend, voice, link, agent.

Adapters are imported only when chosen, so the simulator never loads rospy or rclpy and
the plaintext link never reads certificates.
"""

from __future__ import annotations

import importlib
import inspect
from pathlib import Path
from typing import TYPE_CHECKING

from robot_agent.agent import RobotAgent
from robot_agent.backends.port import BatteryGauge
from robot_agent.backends.sim import SimBackend
from robot_agent.core.in_flight import InFlight
from robot_agent.core.recent_ids import RecentIds
from vahr.domain import load_fleet
from vahr.errors import VahrError
from vahr.protocol import Presence, encode, topics
from vahr.protocol.broker import ClientCredentials, plaintext_loopback
from vahr.speech.errors import SpeechError

if TYPE_CHECKING:
    import asyncio

    from robot_agent.backends.port import NavigationBackend
    from robot_agent.clock import ScaledClock
    from robot_agent.config import AgentConfig
    from robot_agent.link.mqtt5 import Mqtt5Link
    from robot_agent.voice.port import Voice
    from vahr.domain import Fleet
    from vahr.navigation import FleetFloor
    from vahr.protocol.link import Link


def build_backend(config: AgentConfig, fleet: Fleet, clock: ScaledClock) -> NavigationBackend:
    thing = str(config.thing)
    if config.backend == "ros1":
        try:
            from robot_agent.backends.ros1 import Ros1Backend
        except ImportError as err:
            raise VahrError(
                f"--backend ros1 needs ROS 1's rospy, actionlib and move_base_msgs ({err}); "
                "install ros-core and python3-move-base-msgs, then run make setup"
            ) from err
        return Ros1Backend(config.ros, start=fleet.robot(thing).start)
    if config.backend == "nav2":
        try:
            from robot_agent.backends.nav2 import Nav2Backend
        except ImportError as err:
            raise VahrError(
                f"--backend nav2 needs ROS 2's rclpy and nav2_msgs ({err}); run robot-agent "
                "from .venv-ros2 (make setup makes it), or next to the robot's own ROS 2"
            ) from err
        return Nav2Backend(config.nav2, start=fleet.robot(thing).start)
    return SimBackend(
        start=fleet.robot(thing).start,
        clock=clock,
        settings=config.sim,
        floor=robot_floor(fleet),
        battery=fleet.battery_rates(thing),
        chargers=fleet.chargers,
    )


def robot_floor(fleet: Fleet) -> FleetFloor | None:
    """The fleet's map, read and checked, for a simulated robot to plan on; None for a
    drawn floor (the robot drives straight). A bad map is a VahrError in one line."""
    if fleet.floor is None or fleet.floor.map is None:
        return None
    from vahr.navigation import load_floor

    return load_floor(fleet)


def build_voice(config: AgentConfig, link: Link) -> Voice | None:
    """`none`, or `package.module:factory` returning a Voice.

    The factory is called with `thing=` and, for each such parameter it has, `config=` (the
    `AgentConfig`, whose `voice` section is its settings) and `link=` (the agent's own
    `Link`, which a voice in the room speaks over), e.g. `robot_agent.voice.factories:room`.
    """
    spec = config.voice.factory
    if spec == "none":
        return None
    module_name, _, factory_name = spec.partition(":")
    if not factory_name:
        raise VahrError(f"--voice {spec!r}: expected none or package.module:factory")
    try:
        factory = getattr(importlib.import_module(module_name), factory_name)
    except (ImportError, AttributeError) as err:
        raise VahrError(f"--voice {spec!r}: {err}") from err
    if not callable(factory):
        raise VahrError(f"--voice {spec!r}: {factory_name} is not a factory")
    arguments: dict[str, object] = {"thing": config.thing}
    try:
        signature = inspect.signature(factory)
        for name, value in (("config", config), ("link", link)):
            if name in signature.parameters:
                arguments[name] = value
        signature.bind(**arguments)
    except (TypeError, ValueError) as err:
        raise VahrError(f"--voice {spec!r}: not a factory taking thing= ({err})") from err
    try:
        voice: Voice = factory(**arguments)
    except SpeechError as err:
        raise VahrError(f"--voice {spec}: {err}") from err
    return voice


def build_link(
    config: AgentConfig, loop: asyncio.AbstractEventLoop, clock: ScaledClock
) -> Mqtt5Link:
    from robot_agent.link.mqtt5 import LinkSettings, Mqtt5Link, Will

    thing = str(config.thing)
    if config.broker:
        address = plaintext_loopback(config.broker)
        host, port = address.host, address.port
        tls = None
    else:
        host, port = str(config.endpoint), config.port
        tls = ClientCredentials(
            Path(str(config.cert)), Path(str(config.key)), Path(config.ca) if config.ca else None
        )
    will = Will(
        topic=topics.robot_presence(thing),
        payload=encode(Presence(online=False, at=clock.now())),
    )
    return Mqtt5Link(
        LinkSettings(
            client_id=config.client_id or thing,
            host=host,
            port=port,
            tls=tls,
            will=will,
            session=config.mqtt,
        ),
        loop,
    )


def load_robot_fleet(config: AgentConfig) -> Fleet:
    """The fleet, checked to contain this robot (before anything connects)."""
    fleet = load_fleet(config.fleet_file)
    thing = str(config.thing)
    try:
        topics.check_thing(thing)
    except ValueError as err:
        raise VahrError(str(err)) from err
    if thing not in fleet.robot_things:
        raise VahrError(
            f"--thing {thing}: not a robot of the fleet; robots are {', '.join(fleet.robot_things)}"
        )
    return fleet


def build_agent(
    config: AgentConfig,
    fleet: Fleet,
    link: Mqtt5Link,
    clock: ScaledClock,
    voice: Voice | None = None,
) -> RobotAgent:
    thing = str(config.thing)
    state_dir = Path(config.state_dir) / "robots" / thing
    backend = build_backend(config, fleet, clock)
    agent = RobotAgent(
        thing=thing,
        fleet=fleet,
        link=link,
        backend=backend,
        clock=clock,
        recent_ids=RecentIds(state_dir / "recent-ids.json"),
        voice=voice,
        settings=config.executor,
        in_flight=InFlight(state_dir / "in-flight.json"),
    )
    if isinstance(backend, BatteryGauge):
        backend.watch_battery(agent.executor.report_battery)
    return agent
