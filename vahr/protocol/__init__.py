"""The wire contract shared by the skill, the robots, the local stack and the experiment.

Import from here: topic builders (`topics`), messages (`Command`, `Event`, `Presence`),
the reported shadow state (`Reported`), the fleet model (`Fleet`, `load_fleet`), the domain
facts (`WEATHER_ZONES`; `assistant` for the invocation name), and the one error type
decoding raises (`ProtocolError`). `link` is the port MQTT adapters implement and `broker`
how they reach the broker. This package ships in the Lambda, so it
imports only msgspec (and PyYAML lazily, when a fleet file is read).
"""

from __future__ import annotations

from vahr.protocol import topics
from vahr.protocol.errors import ProtocolError
from vahr.protocol.fleet import (
    DEFAULT_FLEET_FILE,
    FLEET_GROUP,
    FLEET_GROUP_NAMES,
    Fleet,
    Group,
    Pose,
    Robot,
    Zone,
    load_fleet,
)
from vahr.protocol.messages import (
    ACTIONS,
    MAX_PAYLOAD_BYTES,
    MOTION_ACTIONS,
    Command,
    Deliver,
    Event,
    EventKind,
    EventPose,
    Navigate,
    NoParams,
    Ping,
    Presence,
    SequentialDelivery,
    SequentialParams,
    Stop,
    WeatherDelivery,
    ZoneParams,
    check_against_fleet,
    check_payload,
    decode_command,
    decode_event,
    decode_presence,
    encode,
    new_command,
    utc_now,
)
from vahr.protocol.shadow import (
    ExperimentState,
    LastCommand,
    Reported,
    Result,
    RobotShadow,
    ShadowPose,
    Status,
    Weather,
    experiment_state_from_payload,
    robot_shadow_from_payload,
)
from vahr.protocol.weather import WEATHER_ZONES, WEATHERS

__all__ = [
    "ACTIONS",
    "DEFAULT_FLEET_FILE",
    "FLEET_GROUP",
    "FLEET_GROUP_NAMES",
    "MAX_PAYLOAD_BYTES",
    "MOTION_ACTIONS",
    "Command",
    "Deliver",
    "Event",
    "EventKind",
    "EventPose",
    "ExperimentState",
    "Fleet",
    "Group",
    "LastCommand",
    "Navigate",
    "NoParams",
    "Ping",
    "Pose",
    "Presence",
    "ProtocolError",
    "Reported",
    "Result",
    "Robot",
    "RobotShadow",
    "SequentialDelivery",
    "SequentialParams",
    "ShadowPose",
    "Status",
    "Stop",
    "Weather",
    "WeatherDelivery",
    "Zone",
    "ZoneParams",
    "check_against_fleet",
    "check_payload",
    "decode_command",
    "decode_event",
    "decode_presence",
    "encode",
    "experiment_state_from_payload",
    "load_fleet",
    "new_command",
    "robot_shadow_from_payload",
    "topics",
    "utc_now",
    "WEATHERS",
    "WEATHER_ZONES",
]
