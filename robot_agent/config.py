"""`robot-agent run` settings, declared once: defaults < config file (YAML) < environment <
flags, parsed and validated at start-up into `AgentConfig`.

Each adapter's settings struct is its section of the config, with its limits: `sim`
(`SimBackend`), `ros` (`Ros1Backend`), `nav2` (`Nav2Backend`), `executor` (the core), `mqtt`
(the awscrt link) and `voice` (which voice, its synthesizer, devices and interpreter). The
adapters take these very structs; nothing copies them field by field.

Environment variables map onto the config in one place, `ENVIRONMENT` below:
`VAHR_AGENT_<FIELD>` for the top-level fields (e.g. `VAHR_AGENT_THING`,
`VAHR_AGENT_BROKER`, `VAHR_AGENT_SIM_SPEED_FACTOR`) and the voice's own `VAHR_*` names.
See docs/robot-agent.md and docs/voice.md for every key.
"""

from __future__ import annotations

import math
import os
import shlex
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
Fraction = Annotated[float, msgspec.Meta(ge=0, le=1)]
NonNegativeInt = Annotated[int, msgspec.Meta(ge=0)]
PositiveInt = Annotated[int, msgspec.Meta(gt=0)]


class SimSettings(msgspec.Struct, kw_only=True, forbid_unknown_fields=True, frozen=True):
    """The simulator backend (`robot_agent.backends.sim`)."""

    speed_mps: Positive = 0.5
    turn_rate_rps: Positive = 1.0
    loader_delay_s: NonNegative = 3.0
    unloader_delay_s: NonNegative = 3.0
    # Simulated seconds between two kinematic steps (and two progress reports).
    tick_s: Positive = 0.25
    # Fault injection: goals to these zones stop moving half way / abort half way.
    stuck_zones: tuple[str, ...] = ()
    fail_zones: tuple[str, ...] = ()
    # Development only: accept faults injected at run time on the robot's fault topic
    # (`vahr fault`; robot_agent.dev_faults). `vahr up` sets it for its robots.
    accept_faults: bool = False


class ExecutorSettings(msgspec.Struct, kw_only=True, forbid_unknown_fields=True, frozen=True):
    """Timing rules of the executor, in simulated seconds (see `ScaledClock`)."""

    stuck_after_s: Positive = 10.0
    sequential_timeout_s: Positive = 300.0
    # How far the peers' clocks may disagree with the sender's: a peer delivery counts for a
    # sequential delivery only if it happened after the command was issued, less this.
    peer_clock_skew_s: NonNegative = 2.0
    listen_timeout_s: Positive = 8.0
    # Wall-clock bound on speaking one sentence, so a hung audio device fails the task.
    speak_timeout_s: Positive = 30.0
    # How often a drive reports `progress`. On AWS every event is a billed message, so by
    # default a robot reports at most once every 5 s and once per quarter of the way (both
    # must hold; `arrived` closes the drive). The local stack asks for more (`vahr up`
    # writes progress_interval_s 1, progress_step 0) because a screen is cheap.
    # Simulated seconds between two reports at least (0: every backend step).
    progress_interval_s: NonNegative = 5.0
    # Fraction of the way covered between two reports at least (0: no bound).
    progress_step: Fraction = 0.25


class Ros1Settings(msgspec.Struct, kw_only=True, forbid_unknown_fields=True, frozen=True):
    """The ROS 1 backend (`robot_agent.backends.ros1`)."""

    # None: use ROS_MASTER_URI from the environment, as every ROS node does.
    master_uri: str | None = None
    action: str = "move_base"
    frame: str = "map"
    node_name: str = "vahr_robot_agent"
    server_timeout_s: Positive = 10.0
    # ROS has no arm: the loading and unloading arms are timed like the simulator's.
    loader_delay_s: NonNegative = 3.0
    unloader_delay_s: NonNegative = 3.0
    # rospy's threads keep a process alive until the node shuts down; the agent's one
    # backend owns the node. Tests that build several backends in one process keep it.
    shutdown_node_on_close: bool = True


class Nav2Settings(msgspec.Struct, kw_only=True, forbid_unknown_fields=True, frozen=True):
    """The ROS 2 Nav2 backend (`robot_agent.backends.nav2`)."""

    # bt_navigator's NavigateToPose action, and the frame the zones' poses are in.
    action: str = "navigate_to_pose"
    frame: str = "map"
    # The robot's sensor_msgs/BatteryState topic (empty: the shadow reports no battery).
    battery_topic: str = "battery_state"
    # The goal's behavior_tree (empty: bt_navigator's default tree).
    behavior_tree: str = ""
    node_name: str = "vahr_robot_agent"
    # None: ROS_DOMAIN_ID from the environment, as every ROS 2 node does.
    domain_id: Annotated[int, msgspec.Meta(ge=0, le=232)] | None = None
    # How long a goal waits for the action server to be there, for it to accept or reject
    # the goal, and for it to confirm a cancel; and how long an accepted goal may go without
    # a word from the server (bt_navigator sends feedback on every tick while it navigates).
    server_timeout_s: Positive = 5.0
    answer_timeout_s: Positive = 5.0
    feedback_timeout_s: Positive = 5.0
    # Nav2 has no arm: the loading and unloading arms are timed like the simulator's.
    loader_delay_s: NonNegative = 3.0
    unloader_delay_s: NonNegative = 3.0


class MqttSettings(msgspec.Struct, kw_only=True, forbid_unknown_fields=True, frozen=True):
    """The awscrt link's session (`robot_agent.link.mqtt5`)."""

    keep_alive_s: NonNegativeInt = 60
    # How long the broker keeps the session (subscriptions, queued QoS 1) while away.
    session_expiry_s: NonNegativeInt = 7 * 24 * 3600
    min_reconnect_delay_ms: PositiveInt = 250
    max_reconnect_delay_ms: PositiveInt = 30_000
    connect_timeout_ms: PositiveInt = 5_000


class LexSettings(msgspec.Struct, kw_only=True, forbid_unknown_fields=True, frozen=True):
    """Amazon Lex V2 as the interpreter, reached with the robot's certificate through the
    AWS IoT credentials provider (`robot_agent.voice.lex`, `iot_credentials`)."""

    bot_id: str | None = None
    bot_alias_id: str | None = None
    locale_id: str = "en_US"
    region: str | None = None
    endpoint_url: str | None = None
    credentials_endpoint: str | None = None
    role_alias: str = "vahr-robot-lex"
    # The robot's certificate for the credentials provider (default: --cert, --key, --ca).
    cert: str | None = None
    key: str | None = None
    ca: str | None = None


class ListenSettings(msgspec.Struct, kw_only=True, forbid_unknown_fields=True, frozen=True):
    """When an answer heard through the sound device starts and ends (`DeviceVoice`)."""

    trailing_silence_ms: PositiveInt = 800
    max_utterance_s: Positive = 15.0
    # Audio kept from before the first loud frame: the start of a word is quiet.
    pre_roll_ms: NonNegativeInt = 300


class VoiceSettings(msgspec.Struct, kw_only=True, forbid_unknown_fields=True, frozen=True):
    """The robot's voice (`robot_agent.voice.factories`)."""

    # `none`, or `package.module:factory` returning a Voice (e.g. ...factories:room).
    factory: str = "none"
    # An espeak-ng voice, or `polly:VOICE`, `gtts[:LANG]`.
    synthesizer: str = "en-us+f2"
    # The sound device's player and recorder commands (default aplay / arecord).
    play_command: tuple[str, ...] | None = None
    record_command: tuple[str, ...] | None = None
    listen: ListenSettings = ListenSettings()
    interpreter: Literal["local", "lex"] = "local"
    lex: LexSettings = LexSettings()


class AgentConfig(msgspec.Struct, kw_only=True, forbid_unknown_fields=True, frozen=True):
    thing: str | None = None
    endpoint: str | None = None
    port: int = 8883
    cert: str | None = None
    key: str | None = None
    ca: str | None = None
    broker: str | None = None
    client_id: str | None = None
    backend: Literal["sim", "ros1", "nav2"] = "sim"
    fleet_file: str | None = None
    state_dir: str = ".state"
    log_level: Literal["DEBUG", "INFO", "WARNING", "ERROR"] = "INFO"
    sim_speed_factor: float = 1.0
    sim: SimSettings = SimSettings()
    executor: ExecutorSettings = ExecutorSettings()
    ros: Ros1Settings = Ros1Settings()
    nav2: Nav2Settings = Nav2Settings()
    mqtt: MqttSettings = MqttSettings()
    voice: VoiceSettings = VoiceSettings()

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
        if self.backend in ("ros1", "nav2") and self.sim_speed_factor != 1.0:
            raise VahrError(
                "--sim-speed-factor applies to the sim backend only; ROS runs in real time"
            )
        return self


_SCALARS = (
    "thing endpoint port cert key ca broker client_id backend fleet_file state_dir log_level "
    "sim_speed_factor"
).split()
# Every environment variable the agent reads, and the key it sets (later rows win).
ENVIRONMENT: dict[str, tuple[str, ...]] = {
    **{ENV_PREFIX + name.upper(): (name,) for name in _SCALARS},
    "VAHR_AGENT_PROGRESS_INTERVAL_S": ("executor", "progress_interval_s"),
    "VAHR_AGENT_PROGRESS_STEP": ("executor", "progress_step"),
    "VAHR_AGENT_VOICE": ("voice", "factory"),
    "VAHR_VOICE": ("voice", "synthesizer"),
    "VAHR_PLAY_COMMAND": ("voice", "play_command"),
    "VAHR_RECORD_COMMAND": ("voice", "record_command"),
    "VAHR_INTERPRETER": ("voice", "interpreter"),
    "AWS_REGION": ("voice", "lex", "region"),
    "VAHR_LEX_REGION": ("voice", "lex", "region"),
    "VAHR_LEX_BOT_ID": ("voice", "lex", "bot_id"),
    "VAHR_LEX_BOT_ALIAS_ID": ("voice", "lex", "bot_alias_id"),
    "VAHR_LEX_LOCALE": ("voice", "lex", "locale_id"),
    "VAHR_LEX_ENDPOINT_URL": ("voice", "lex", "endpoint_url"),
    "VAHR_IOT_CREDENTIALS_ENDPOINT": ("voice", "lex", "credentials_endpoint"),
    "VAHR_IOT_ROLE_ALIAS": ("voice", "lex", "role_alias"),
    "VAHR_ROBOT_CERT": ("voice", "lex", "cert"),
    "VAHR_ROBOT_KEY": ("voice", "lex", "key"),
    "VAHR_ROBOT_CA": ("voice", "lex", "ca"),
}
# Commands are written as a shell would split them.
_COMMANDS = {("voice", "play_command"), ("voice", "record_command")}
# Flags whose argparse destination differs from the config key, or that are not config.
_FLAG_KEYS: dict[str, tuple[str, ...]] = {
    **{name: (name,) for name in _SCALARS if name != "fleet_file"},
    "fleet": ("fleet_file",),
    "voice": ("voice", "factory"),
}


def load_config(args: argparse.Namespace, environ: Mapping[str, str] | None = None) -> AgentConfig:
    """Merge the config file, the environment and the flags, then validate once."""
    merged: dict[str, Any] = {}
    config_file = getattr(args, "config", None)
    if config_file:
        merged.update(_read_file(Path(config_file)))
        if isinstance(merged.get("voice"), str):
            # `voice: package.module:factory`, as written before the voice had a section.
            merged["voice"] = {"factory": merged["voice"]}
    env = os.environ if environ is None else environ
    for name, key in ENVIRONMENT.items():
        value = env.get(name)
        if value is not None and value != "":
            _set(merged, key, shlex.split(value) if key in _COMMANDS else value)
    for flag, key in _FLAG_KEYS.items():
        value = getattr(args, flag, None)
        if value is not None:
            _set(merged, key, value)
    return config_from(merged)


def config_from(settings: Mapping[str, Any]) -> AgentConfig:
    """Validate merged settings into an `AgentConfig`; errors name the key."""
    try:
        return msgspec.convert(settings, AgentConfig, strict=False)
    except msgspec.ValidationError as err:
        raise VahrError(f"configuration: {from_validation_error(err)}") from err


def _set(merged: dict[str, Any], key: tuple[str, ...], value: object) -> None:
    section = merged
    for part in key[:-1]:
        inner = section.get(part)
        if not isinstance(inner, dict):
            inner = section[part] = {}
        section = inner
    section[key[-1]] = value


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
