"""The skill's configuration, read once from the environment at cold start.

Every setting has a default, so the handler runs with only a region configured:

| variable | default | meaning |
| --- | --- | --- |
| `AWS_ENDPOINT_URL_IOT_DATA_PLANE` | unset | iot-data endpoint URL (boto3's own variable) |
| `VAHR_IOT_DATA_ENDPOINT` | unset | iot-data endpoint set by the CDK stack (URL or host name) |
| `AWS_ENDPOINT_URL_IOT` | unset | IoT control plane for fleet indexing (see `index_endpoint`) |
| `VAHR_SKILL_ID` | unset | the skill whose requests are served; any other is refused |
| `VAHR_SKILL_ID_PARAMETER` | unset | an SSM parameter holding it (a stack making the skill) |
| `VAHR_ALLOW_ANY_SKILL` | false | on Lambda with no skill id, serve any skill instead of none |
| `AWS_LAMBDA_FUNCTION_NAME` | unset | set by Lambda: there, no skill id means none is served |
| `VAHR_ACK_TIMEOUT_S` | 2.5 | how long to wait for robots to acknowledge a command (0-6 s) |
| `VAHR_FLEET_FILE` | bundled fleet.yaml | the fleet definition |
| `VAHR_LOG_LEVEL` | INFO | DEBUG, INFO, WARNING or ERROR |
| `VAHR_DISPATCHER_FUNCTION` | unset | the fleet dispatcher function (the CDK stack sets it) |
| `VAHR_USERS_TABLE` | unset | the DynamoDB table of people and their roles (the stack sets it) |
| `VAHR_USERS_FILE` | unset | a users file instead (`vahr up --users`); neither: all may do all |
| `VAHR_AUDIT_TABLE` | unset | the DynamoDB table of the audit trail (the stack sets it) |
| `VAHR_CONFIRM` | unset | true or false: confirm fleet-wide commands first (else the fleet file) |
"""

from __future__ import annotations

import os
from typing import TYPE_CHECKING

import msgspec

from skill.errors import ConfigError

if TYPE_CHECKING:
    from collections.abc import Mapping

# Alexa waits 8 s for an answer; publishing and speaking need some of it.
MAX_ACK_TIMEOUT_S = 6.0
DEFAULT_ACK_TIMEOUT_S = 2.5
DEFAULT_LOG_LEVEL = "INFO"
LOG_LEVELS = ("DEBUG", "INFO", "WARNING", "ERROR", "CRITICAL")


class SkillConfig(msgspec.Struct, frozen=True):
    """Validated settings; build it with `from_env` (or directly in tests and the simulator)."""

    data_endpoint: str | None = None
    # The one skill served (skill.skill_gate): given, or read from an SSM parameter.
    skill_id: str | None = None
    skill_id_parameter: str | None = None
    allow_any_skill: bool = False
    on_lambda: bool = False
    ack_timeout_s: float = DEFAULT_ACK_TIMEOUT_S
    fleet_file: str | None = None
    log_level: str = DEFAULT_LOG_LEVEL
    # Where boto3 finds no region (a local endpoint needs none), sign for this one.
    fallback_region: str = "us-east-1"
    # The fleet dispatcher's function name on AWS (skill.task_desk.task_desk).
    dispatcher_function: str | None = None
    # The IoT control plane's URL for fleet indexing, when not boto3's default.
    control_endpoint: str | None = None
    # Who may do what (skill.speakers): a DynamoDB table, or a users file; neither is open.
    users_table: str | None = None
    users_file: str | None = None
    # Where every request's record goes (skill.trail): a DynamoDB table on AWS; the local
    # data plane when `data_endpoint` is a local one.
    audit_table: str | None = None
    # Whether fleet-wide commands are confirmed first; None: as the fleet file says, else
    # whenever people are known.
    confirm: bool | None = None

    @property
    def people_known(self) -> bool:
        return self.users_table is not None or self.users_file is not None

    @property
    def index_endpoint(self) -> str | None:
        """Where fleet-indexing calls go: the configured control plane; else the data
        endpoint when it is a local `http://` one (the local data plane answers both);
        else None, boto3's default (AWS)."""
        if self.control_endpoint:
            return self.control_endpoint
        local = self.data_endpoint is not None and self.data_endpoint.startswith("http://")
        return self.data_endpoint if local else None

    @classmethod
    def from_env(cls, environ: Mapping[str, str] | None = None) -> SkillConfig:
        env = os.environ if environ is None else environ
        endpoint = _blank_to_none(env.get("AWS_ENDPOINT_URL_IOT_DATA_PLANE")) or _blank_to_none(
            env.get("VAHR_IOT_DATA_ENDPOINT")
        )
        return cls(
            data_endpoint=_as_url(endpoint) if endpoint else None,
            skill_id=_blank_to_none(env.get("VAHR_SKILL_ID")),
            skill_id_parameter=_blank_to_none(env.get("VAHR_SKILL_ID_PARAMETER")),
            allow_any_skill=_flag(env.get("VAHR_ALLOW_ANY_SKILL"), "VAHR_ALLOW_ANY_SKILL"),
            on_lambda=_blank_to_none(env.get("AWS_LAMBDA_FUNCTION_NAME")) is not None,
            ack_timeout_s=_ack_timeout(env.get("VAHR_ACK_TIMEOUT_S")),
            fleet_file=_blank_to_none(env.get("VAHR_FLEET_FILE")),
            log_level=_log_level(env.get("VAHR_LOG_LEVEL")),
            dispatcher_function=_blank_to_none(env.get("VAHR_DISPATCHER_FUNCTION")),
            control_endpoint=_blank_to_none(env.get("AWS_ENDPOINT_URL_IOT")),
            users_table=_blank_to_none(env.get("VAHR_USERS_TABLE")),
            users_file=_blank_to_none(env.get("VAHR_USERS_FILE")),
            audit_table=_blank_to_none(env.get("VAHR_AUDIT_TABLE")),
            confirm=(
                None
                if _blank_to_none(env.get("VAHR_CONFIRM")) is None
                else _flag(env.get("VAHR_CONFIRM"), "VAHR_CONFIRM")
            ),
        )


def _blank_to_none(value: str | None) -> str | None:
    return value.strip() if value and value.strip() else None


def _flag(raw: str | None, name: str) -> bool:
    text = (raw or "").strip().lower()
    if text in ("", "false", "0", "no"):
        return False
    if text in ("true", "1", "yes"):
        return True
    raise ConfigError(f"{name}: {raw!r} is not true or false")


def _as_url(endpoint: str) -> str:
    # IoT's DescribeEndpoint returns a bare host name; boto3 wants a URL.
    return endpoint if "://" in endpoint else f"https://{endpoint}"


def _ack_timeout(raw: str | None) -> float:
    if _blank_to_none(raw) is None:
        return DEFAULT_ACK_TIMEOUT_S
    assert raw is not None
    try:
        value = float(raw)
    except ValueError:
        raise ConfigError(f"VAHR_ACK_TIMEOUT_S: {raw!r} is not a number of seconds") from None
    if not 0 < value <= MAX_ACK_TIMEOUT_S:
        raise ConfigError(
            f"VAHR_ACK_TIMEOUT_S: {value:g} is out of range; use more than 0 and at most "
            f"{MAX_ACK_TIMEOUT_S:g} seconds (Alexa waits 8 s for an answer)"
        )
    return value


def _log_level(raw: str | None) -> str:
    level = (_blank_to_none(raw) or DEFAULT_LOG_LEVEL).upper()
    if level not in LOG_LEVELS:
        raise ConfigError(f"VAHR_LOG_LEVEL: {raw!r} is not one of {', '.join(LOG_LEVELS)}")
    return level
