"""`robot-agent run`: run one robot until SIGINT or SIGTERM."""

from __future__ import annotations

import asyncio
import json
import logging
import signal
from typing import TYPE_CHECKING

from robot_agent.config import load_config, printable
from vahr.cli_router import setup_logging

if TYPE_CHECKING:
    import argparse

    from robot_agent.config import AgentConfig

log = logging.getLogger("robot_agent")

SHUTDOWN_TIMEOUT_S = 5.0


def configure(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--thing", help="the robot's thing name (one of fleet.yaml's robots)")
    parser.add_argument("--config", help="YAML file of settings (flags and VAHR_AGENT_* win)")
    link = parser.add_argument_group("connection (mTLS, or plaintext to a loopback broker)")
    link.add_argument("--endpoint", help="MQTT host: the AWS IoT data endpoint or the local stack")
    link.add_argument("--port", type=int, help="MQTT port for --endpoint (default 8883)")
    link.add_argument("--cert", help="the robot's certificate (PEM)")
    link.add_argument("--key", help="the robot's private key (PEM)")
    link.add_argument("--ca", help="the CA that signed the broker's certificate (PEM)")
    link.add_argument("--broker", help="plaintext mqtt://127.0.0.1:PORT (development only)")
    link.add_argument("--client-id", help="MQTT client id (default: the thing name)")
    parser.add_argument(
        "--backend",
        choices=["sim", "ros1", "nav2"],
        help="navigation backend (default sim; nav2 runs from .venv-ros2)",
    )
    parser.add_argument(
        "--sim-speed-factor", type=float, help="run simulated time this many times faster"
    )
    parser.add_argument("--fleet", help="fleet file (default: the bundled fleet.yaml)")
    parser.add_argument("--state-dir", help="where the robot keeps its state (default .state)")
    parser.add_argument("--voice", help="none, or package.module:factory returning a Voice")
    parser.add_argument(
        "--log-level", choices=["DEBUG", "INFO", "WARNING", "ERROR"], help="default INFO"
    )
    parser.add_argument(
        "--print-config", action="store_true", help="print the effective settings as JSON and exit"
    )


def run(args: argparse.Namespace) -> int:
    config = load_config(args)
    if args.print_config:
        print(json.dumps(printable(config), indent=2, sort_keys=True))
        return 0
    config.check()
    setup_logging(config.log_level)
    return asyncio.run(serve(config))


async def serve(config: AgentConfig) -> int:
    from robot_agent.assembly import build_agent, build_link, build_voice, load_robot_fleet
    from robot_agent.clock import ScaledClock

    # Everything that can be wrong in the settings fails before anything connects.
    fleet = load_robot_fleet(config)
    loop = asyncio.get_running_loop()
    clock = ScaledClock(config.sim_speed_factor)
    link = build_link(config, loop, clock)
    voice = build_voice(config, link)
    agent = build_agent(config, fleet, link, clock, voice)
    agent.attach()
    if config.sim.accept_faults:
        from robot_agent.dev_faults import DevFaults

        DevFaults(thing=agent.thing, link=link, backend=agent.executor.backend).attach()
    stopping = asyncio.Event()
    for signum in (signal.SIGINT, signal.SIGTERM):
        loop.add_signal_handler(signum, stopping.set)
    log.info(
        "%s: starting (%s backend, link %s)",
        agent.thing,
        config.backend,
        config.broker or f"mqtts://{config.endpoint}:{config.port}",
    )
    await link.start()
    try:
        await stopping.wait()
    finally:
        log.info("%s: shutting down", agent.thing)
        await agent.shut_down()
        await link.flush(SHUTDOWN_TIMEOUT_S)
        await link.stop(SHUTDOWN_TIMEOUT_S)
    log.info("%s: stopped", agent.thing)
    return 0
