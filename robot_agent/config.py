"""`robot-agent run` configuration: defaults < config file (YAML) < environment < flags.

Parsed and validated once, at start-up, into `AgentConfig`. Environment variables are
`VAHR_AGENT_<FIELD>` for the top-level fields (e.g. `VAHR_AGENT_THING`,
`VAHR_AGENT_BROKER`, `VAHR_AGENT_SIM_SPEED_FACTOR`); the nested sections (`sim`,
`executor`, `ros`, `mqtt`) come from the file. See docs/robot-agent.md for every key.
"""

from __future__ import annotations

import math
import os
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any, Literal

import msgspec

from vahr.errors import VahrError
from vahr.protocol.errors import from_validation_error

if TYPE_CHECKING:
    import argparse
    from collections.abc import Mapping

ENV_PREFIX = "VAHR_AGENT_"

# A zero speed or tick would never arrive (or divide by zero) and a negative delay is
# meaningless, so such values are refused at start-up with the key's name.
Positive = Annotated[float, msgspec.Meta(gt=0)]
NonNegative = Annotated[float, msgspec.Meta(ge=0)]
NonNegativeInt = Annotated[int, msgspec.Meta(ge=0)]
PositiveInt = Annotated[int, msgspec.Meta(gt=0)]


class SimConfig(msgspec.Struct, kw_only=True, forbid_unknown_fields=True, frozen=True):
    speed_mps: Positive = 0.5
    turn_rate_rps: Positive = 1.0
    loader_delay_s: NonNegative = 3.0
    unloader_delay_s: NonNegative = 3.0
    tick_s: Positive = 0.25
    stuck_zones: list[str] = []
    fail_zones: list[str] = []


class ExecutorConfig(msgspec.Struct, kw_only=True, forbid_unknown_fields=True, frozen=True):
    stuck_after_s: Positive = 10.0
    sequential_timeout_s: Positive = 300.0
    peer_clock_skew_s: NonNegative = 2.0
    listen_timeout_s: Positive = 8.0
    speak_timeout_s: Positive = 30.0
    progress_interval_s: NonNegative = 1.0


class RosConfig(msgspec.Struct, kw_only=True, forbid_unknown_fields=True, frozen=True):
    # None: use ROS_MASTER_URI from the environment, as every ROS node does.
    master_uri: str | None = None
    action: str = "move_base"
    frame: str = "map"
    node_name: str = "vahr_robot_agent"
    server_timeout_s: Positive = 10.0
    # ROS has no arm: the loading and unloading arms are timed like the simulator's.
    loader_delay_s: NonNegative = 3.0
    unloader_delay_s: NonNegative = 3.0


class MqttConfig(msgspec.Struct, kw_only=True, forbid_unknown_fields=True, frozen=True):
    keep_alive_s: NonNegativeInt = 60
    session_expiry_s: NonNegativeInt = 7 * 24 * 3600
    min_reconnect_delay_ms: PositiveInt = 250
    max_reconnect_delay_ms: PositiveInt = 30_000


class AgentConfig(msgspec.Struct, kw_only=True, forbid_unknown_fields=True, frozen=True):
    thing: str | None = None
    endpoint: str | None = None
    port: int = 8883
    cert: str | None = None
    key: str | None = None
    ca: str | None = None
    broker: str | None = None
    client_id: str | None = None
    backend: Literal["sim", "ros1"] = "sim"
    fleet_file: str | None = None
    state_dir: str = ".state"
    log_level: Literal["DEBUG", "INFO", "WARNING", "ERROR"] = "INFO"
    sim_speed_factor: float = 1.0
    voice: str = "none"
    sim: SimConfig = SimConfig()
    executor: ExecutorConfig = ExecutorConfig()
    ros: RosConfig = RosConfig()
    mqtt: MqttConfig = MqttConfig()

    def check(self) -> AgentConfig:
        """The rules that span fields; raises VahrError naming the flag to fix."""
        if not self.thing:
            raise VahrError("--thing is required (or `thing` in --config, or VAHR_AGENT_THING)")
        if not 0 < self.port < 65536:
            raise VahrError(f"--port {self.port}: expected a TCP port (1-65535)")
        if self.broker and self.endpoint:
            raise VahrError(
                "give either --broker (plaintext loopback) or --endpoint (mTLS), not both"
            )
        if not self.broker and not self.endpoint:
            raise VahrError(
                "give --endpoint with --cert, --key and --ca, or --broker mqtt://127.0.0.1:PORT"
            )
        if self.endpoint:
            missing = [f"--{name}" for name in ("cert", "key") if not getattr(self, name)]
            if missing:
                raise VahrError(f"--endpoint needs {' and '.join(missing)}")
            for name in ("cert", "key", "ca"):
                value = getattr(self, name)
                if value and not Path(value).is_file():
                    raise VahrError(f"--{name} {value}: no such file")
        if not 0 < self.sim_speed_factor < math.inf:
            raise VahrError("--sim-speed-factor must be greater than 0")
        if self.backend == "ros1" and self.sim_speed_factor != 1.0:
            raise VahrError(
                "--sim-speed-factor applies to the sim backend only; ROS runs in real time"
            )
        return self


# Flags whose argparse destination differs from the config key, or that are not config.
_FLAG_KEYS = {
    "thing": "thing",
    "endpoint": "endpoint",
    "port": "port",
    "cert": "cert",
    "key": "key",
    "ca": "ca",
    "broker": "broker",
    "client_id": "client_id",
    "backend": "backend",
    "fleet": "fleet_file",
    "state_dir": "state_dir",
    "log_level": "log_level",
    "sim_speed_factor": "sim_speed_factor",
    "voice": "voice",
}
_SCALARS = (
    "thing endpoint port cert key ca broker client_id backend fleet_file state_dir log_level "
    "sim_speed_factor voice"
).split()


def load_config(args: argparse.Namespace, environ: Mapping[str, str] | None = None) -> AgentConfig:
    """Merge the config file, the environment and the flags, then validate once."""
    merged: dict[str, Any] = {}
    config_file = getattr(args, "config", None)
    if config_file:
        merged.update(_read_file(Path(config_file)))
    env = os.environ if environ is None else environ
    for name in _SCALARS:
        value = env.get(ENV_PREFIX + name.upper())
        if value is not None and value != "":
            merged[name] = value
    for flag, key in _FLAG_KEYS.items():
        value = getattr(args, flag, None)
        if value is not None:
            merged[key] = value
    try:
        config = msgspec.convert(merged, AgentConfig, strict=False)
    except msgspec.ValidationError as err:
        raise VahrError(f"configuration: {from_validation_error(err)}") from err
    return config


def _read_file(path: Path) -> dict[str, Any]:
    try:
        loaded = msgspec.yaml.decode(path.read_bytes())
    except OSError as err:
        raise VahrError(f"--config {path}: {err.strerror}") from err
    except msgspec.DecodeError as err:
        raise VahrError(f"--config {path}: not valid YAML ({err})") from err
    if loaded is None:
        return {}
    if not isinstance(loaded, dict):
        raise VahrError(f"--config {path}: expected a mapping of settings")
    return loaded


def printable(config: AgentConfig) -> dict[str, Any]:
    """The effective configuration as JSON-ready data (it holds paths, never key material)."""
    result: dict[str, Any] = msgspec.to_builtins(config)
    return result
