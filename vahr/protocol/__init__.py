"""The wire contract: what crosses MQTT between the skill, the robots, the station and the
hosts, and nothing else.

Import from here: topic builders (`topics`), messages (`Command`, `Event`, `Presence`,
`ReportedPose`), the reported shadow state (`Reported`), and the one error type decoding
raises (`ProtocolError`). `link` is the port MQTT adapters implement, `broker` how they reach
the broker, `announcements`, `fault_request` and `station_topics` the messages of the
assistant's, the fault injector's and the station's topics, `lost_tasks` what the
dispatcher function tells the announcer function of a task it lost, and `conversation` what
the skill and the assistant keep of a conversation. Every Lambda and robot imports it, so it
imports only msgspec; the domain (the fleet, its words) is `vahr.domain`.
"""

from __future__ import annotations

from vahr.protocol import topics
from vahr.protocol.errors import ProtocolError
from vahr.protocol.messages import (
    ACTIONS,
    MAX_PAYLOAD_BYTES,
    MOTION_ACTIONS,
    Command,
    Deliver,
    Event,
    EventKind,
    Navigate,
    NoParams,
    Ping,
    Presence,
    ReportedPose,
    SequentialDelivery,
    SequentialParams,
    Stop,
    WeatherDelivery,
    ZoneClosures,
    ZoneParams,
    check_against_fleet,
    check_payload,
    decode_command,
    decode_event,
    decode_presence,
    decode_zone_closures,
    encode,
    new_command,
    utc_now,
)
from vahr.protocol.shadow import (
    Battery,
    ExperimentState,
    LastCommand,
    Reported,
    Result,
    RobotShadow,
    Status,
    Weather,
    experiment_state_from_payload,
    robot_shadow_from_payload,
)

__all__ = [
    "ACTIONS",
    "MAX_PAYLOAD_BYTES",
    "MOTION_ACTIONS",
    "Battery",
    "Command",
    "Deliver",
    "Event",
    "EventKind",
    "ReportedPose",
    "ExperimentState",
    "LastCommand",
    "Navigate",
    "NoParams",
    "Ping",
    "Presence",
    "ProtocolError",
    "Reported",
    "Result",
    "RobotShadow",
    "SequentialDelivery",
    "SequentialParams",
    "Status",
    "Stop",
    "Weather",
    "WeatherDelivery",
    "ZoneClosures",
    "ZoneParams",
    "check_against_fleet",
    "check_payload",
    "decode_command",
    "decode_event",
    "decode_presence",
    "decode_zone_closures",
    "encode",
    "experiment_state_from_payload",
    "new_command",
    "robot_shadow_from_payload",
    "topics",
    "utc_now",
]
