"""`robot-agent swarm`: run many simulated robots of a fleet file in this one process.

The robots share one MQTT connection (see `robot_agent.swarm`), so the identity given
must be allowed to speak for all of them: a plaintext loopback `--broker`, or `--endpoint`
with the local stack's service certificate. Settings come from `--config` (its `sim` and
`executor` sections apply to every robot), the environment and the flags, as for
`robot-agent run`. Runs until SIGINT or SIGTERM.
"""

from __future__ import annotations

import asyncio
import logging
import signal
from pathlib import Path
from typing import TYPE_CHECKING

import msgspec

from robot_agent.config import load_config
from vahr.cli_router import setup_logging
from vahr.domain import load_fleet
from vahr.errors import VahrError
from vahr.protocol.broker import ClientCredentials

if TYPE_CHECKING:
    import argparse

    from robot_agent.config import AgentConfig
    from vahr.domain import Fleet

log = logging.getLogger("robot_agent")

SHUTDOWN_TIMEOUT_S = 10.0


def configure(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--count", type=int, help="run the fleet's first N robots (default: all of them)"
    )
    parser.add_argument("--fleet", help="fleet file (default: the bundled fleet.yaml)")
    parser.add_argument("--config", help="YAML file of settings (flags and VAHR_AGENT_* win)")
    link = parser.add_argument_group("connection (one for every robot)")
    link.add_argument("--endpoint", help="MQTT host of an mTLS listener")
    link.add_argument("--port", type=int, help="MQTT port for --endpoint (default 8883)")
    link.add_argument("--cert", help="a certificate allowed to speak for every robot (PEM)")
    link.add_argument("--key", help="its private key (PEM)")
    link.add_argument("--ca", help="the CA that signed the broker's certificate (PEM)")
    link.add_argument("--broker", help="plaintext mqtt://127.0.0.1:PORT (development only)")
    link.add_argument("--client-id", help="MQTT client id (default: vahr-swarm-RANDOM)")
    parser.add_argument(
        "--sim-speed-factor", type=float, help="run simulated time this many times faster"
    )
    parser.add_argument("--state-dir", help="where the robots keep their state (default .state)")
    parser.add_argument(
        "--log-level", choices=["DEBUG", "INFO", "WARNING", "ERROR"], help="default INFO"
    )


def run(args: argparse.Namespace) -> int:
    config = load_config(args)
    fleet = load_fleet(config.fleet_file)
    count = len(fleet.robots) if args.count is None else args.count
    if not 1 <= count <= len(fleet.robots):
        raise VahrError(
            f"--count {count}: the fleet has {len(fleet.robots)} robots; give 1 to "
            f"{len(fleet.robots)}"
        )
    things = list(fleet.robot_things[:count])
    # The connection's rules are one robot's: check them as that robot's would be.
    config = msgspec.structs.replace(config, thing=things[0]).check()
    setup_logging(config.log_level)
    return asyncio.run(serve(config, fleet=fleet, things=things))


async def serve(config: AgentConfig, *, fleet: Fleet, things: list[str]) -> int:
    from robot_agent.swarm import Swarm

    tls = None
    if config.endpoint:
        tls = ClientCredentials(
            Path(str(config.cert)), Path(str(config.key)), Path(config.ca) if config.ca else None
        )
    broker = config.broker or f"mqtts://{config.endpoint}:{config.port}"
    swarm = Swarm(
        fleet=fleet,
        things=things,
        broker=broker,
        speed_factor=config.sim_speed_factor,
        sim=config.sim,
        settings=config.executor,
        state_dir=Path(config.state_dir),
        client_id=config.client_id,
        tls=tls,
    )
    loop = asyncio.get_running_loop()
    stopping = asyncio.Event()
    for signum in (signal.SIGINT, signal.SIGTERM):
        loop.add_signal_handler(signum, stopping.set)
    # Building and connecting 1,000 robots takes a few seconds on a busy machine.
    await swarm.start(timeout_s=30.0)
    log.info("swarm: %d robots online on %s", len(things), broker)
    try:
        await stopping.wait()
    finally:
        log.info("swarm: shutting down")
        await swarm.stop(SHUTDOWN_TIMEOUT_S)
    log.info("swarm: stopped")
    return 0
