"""Build the parts of one robot from its configuration: clock, backend, voice, link, agent.

Adapters are imported only when chosen, so the simulator never loads rospy and the
plaintext link never reads certificates.
"""

from __future__ import annotations

import importlib
import inspect
from pathlib import Path
from typing import TYPE_CHECKING

from robot_agent.agent import RobotAgent
from robot_agent.backends.sim import SimBackend, SimSettings
from robot_agent.core.executor import ExecutorSettings
from robot_agent.core.recent_ids import RecentIds
from robot_agent.voice.port import VoiceError
from vahr.errors import VahrError
from vahr.protocol import Presence, encode, load_fleet, topics

if TYPE_CHECKING:
    import asyncio

    from robot_agent.backends.port import NavigationBackend
    from robot_agent.config import AgentConfig
    from robot_agent.core.clock import ScaledClock
    from robot_agent.link.mqtt5 import Mqtt5Link
    from robot_agent.voice.port import Voice
    from vahr.protocol import Fleet


def build_backend(config: AgentConfig, fleet: Fleet, clock: ScaledClock) -> NavigationBackend:
    thing = str(config.thing)
    if config.backend == "ros1":
        try:
            from robot_agent.backends.ros1 import Ros1Backend, Ros1Settings
        except ImportError as err:
            raise VahrError(
                f"--backend ros1 needs ROS 1's rospy, actionlib and move_base_msgs ({err}); "
                "install ros-core and python3-move-base-msgs, then run make setup"
            ) from err

        ros = config.ros
        return Ros1Backend(
            Ros1Settings(
                master_uri=ros.master_uri,
                action=ros.action,
                frame=ros.frame,
                node_name=ros.node_name,
                server_timeout_s=ros.server_timeout_s,
                loader_delay_s=ros.loader_delay_s,
                unloader_delay_s=ros.unloader_delay_s,
            ),
            start=fleet.robot(thing).start,
        )
    sim = config.sim
    return SimBackend(
        start=fleet.robot(thing).start,
        clock=clock,
        settings=SimSettings(
            speed_mps=sim.speed_mps,
            turn_rate_rps=sim.turn_rate_rps,
            loader_delay_s=sim.loader_delay_s,
            unloader_delay_s=sim.unloader_delay_s,
            tick_s=sim.tick_s,
            stuck_zones=tuple(sim.stuck_zones),
            fail_zones=tuple(sim.fail_zones),
        ),
    )


def build_voice(config: AgentConfig) -> Voice | None:
    """`none`, or `package.module:factory` returning a Voice.

    The factory is called with `thing=` and, when it has such a parameter, `config=` (the
    `AgentConfig`), e.g. `robot_agent.voice.factories:room`.
    """
    if config.voice == "none":
        return None
    module_name, _, factory_name = config.voice.partition(":")
    if not factory_name:
        raise VahrError(f"--voice {config.voice!r}: expected none or package.module:factory")
    try:
        factory = getattr(importlib.import_module(module_name), factory_name)
    except (ImportError, AttributeError) as err:
        raise VahrError(f"--voice {config.voice!r}: {err}") from err
    if not callable(factory):
        raise VahrError(f"--voice {config.voice!r}: {factory_name} is not a factory")
    arguments: dict[str, object] = {"thing": config.thing}
    try:
        signature = inspect.signature(factory)
        # Factories that can reuse the agent's connection settings take them as `config`.
        if "config" in signature.parameters:
            arguments["config"] = config
        signature.bind(**arguments)
    except (TypeError, ValueError) as err:
        raise VahrError(f"--voice {config.voice!r}: not a factory taking thing= ({err})") from err
    try:
        voice: Voice = factory(**arguments)
    except VoiceError as err:
        raise VahrError(f"--voice {config.voice}: {err}") from err
    return voice


def executor_settings(config: AgentConfig) -> ExecutorSettings:
    e = config.executor
    return ExecutorSettings(
        stuck_after_s=e.stuck_after_s,
        sequential_timeout_s=e.sequential_timeout_s,
        peer_clock_skew_s=e.peer_clock_skew_s,
        listen_timeout_s=e.listen_timeout_s,
        speak_timeout_s=e.speak_timeout_s,
        progress_interval_s=e.progress_interval_s,
    )


def build_link(
    config: AgentConfig, loop: asyncio.AbstractEventLoop, clock: ScaledClock
) -> Mqtt5Link:
    from robot_agent.link.mqtt5 import LinkSettings, Mqtt5Link, MutualTls, Will, plaintext_broker

    thing = str(config.thing)
    if config.broker:
        host, port = plaintext_broker(config.broker)
        tls = None
    else:
        host, port = str(config.endpoint), config.port
        tls = MutualTls(
            cert=Path(str(config.cert)),
            key=Path(str(config.key)),
            ca=Path(config.ca) if config.ca else None,
        )
    will = Will(
        topic=topics.robot_presence(thing),
        payload=encode(Presence(online=False, at=clock.now())),
    )
    mqtt = config.mqtt
    return Mqtt5Link(
        LinkSettings(
            client_id=config.client_id or thing,
            host=host,
            port=port,
            tls=tls,
            will=will,
            keep_alive_s=mqtt.keep_alive_s,
            session_expiry_s=mqtt.session_expiry_s,
            min_reconnect_delay_ms=mqtt.min_reconnect_delay_ms,
            max_reconnect_delay_ms=mqtt.max_reconnect_delay_ms,
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
    return RobotAgent(
        thing=thing,
        fleet=fleet,
        link=link,
        backend=build_backend(config, fleet, clock),
        clock=clock,
        recent_ids=RecentIds(state_dir / "recent-ids.json"),
        voice=voice,
        settings=executor_settings(config),
    )
