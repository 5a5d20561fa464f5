"""The dispatcher's configuration, read once from the environment at cold start.

| variable | default | meaning |
| --- | --- | --- |
| `VAHR_TASK_TABLE` | required | the DynamoDB table of tasks (the CDK stack sets it) |
| `VAHR_IOT_DATA_ENDPOINT` | boto3's default | iot-data endpoint commands are published at |
| `VAHR_FLEET_INDEX` | `AWS_Things` | the fleet index searched for candidate robots |
| `VAHR_FLEET_FILE` | bundled fleet.yaml | the fleet definition (zones, groups, floor) |
| `VAHR_DISTANCES_FILE` | bundled fleet-distances.bin | a map fleet's zone distances (grid_routes) |
| `VAHR_CLOSED_TASK_DAYS` | 30 | how long a finished or cancelled task stays readable |
| `VAHR_LOG_LEVEL` | INFO | DEBUG, INFO, WARNING or ERROR |
| `VAHR_AUDIT_TABLE` | unset | the audit trail's table: tasks given by the dispatcher itself |
| `VAHR_ANNOUNCER_FUNCTION` | unset | the announcer function told of lost tasks (unset: logged) |
"""

from __future__ import annotations

import os
from typing import TYPE_CHECKING

import msgspec

from dispatcher.errors import ConfigError
from vahr.dispatch.grid_routes import BUNDLED_FILE

if TYPE_CHECKING:
    from collections.abc import Mapping

LOG_LEVELS = ("DEBUG", "INFO", "WARNING", "ERROR")
# AWS IoT's name for the thing index, the only one that holds shadows.
THING_INDEX = "AWS_Things"


class DispatcherConfig(msgspec.Struct, frozen=True, kw_only=True):
    table: str
    iot_data_endpoint: str | None = None
    index_name: str = THING_INDEX
    fleet_file: str | None = None
    distances_file: str = BUNDLED_FILE
    closed_task_days: int = 30
    log_level: str = "INFO"
    audit_table: str | None = None
    announcer_function: str | None = None

    @classmethod
    def from_env(cls, environ: Mapping[str, str] | None = None) -> DispatcherConfig:
        env = os.environ if environ is None else environ
        table = env.get("VAHR_TASK_TABLE", "").strip()
        if not table:
            raise ConfigError("VAHR_TASK_TABLE: not set (the CDK stack sets it)")
        endpoint = env.get("VAHR_IOT_DATA_ENDPOINT", "").strip() or None
        if endpoint is not None and not endpoint.startswith(("https://", "http://127.0.0.1")):
            endpoint = f"https://{endpoint}"
        days_text = env.get("VAHR_CLOSED_TASK_DAYS", "").strip() or "30"
        try:
            days = int(days_text)
        except ValueError:
            raise ConfigError(f"VAHR_CLOSED_TASK_DAYS: {days_text!r} is not a number") from None
        if not 1 <= days <= 365:
            raise ConfigError(f"VAHR_CLOSED_TASK_DAYS: {days} must be 1 to 365")
        level = (env.get("VAHR_LOG_LEVEL") or "INFO").strip().upper()
        if level not in LOG_LEVELS:
            raise ConfigError(f"VAHR_LOG_LEVEL: {level!r} must be {', '.join(LOG_LEVELS)}")
        return cls(
            table=table,
            iot_data_endpoint=endpoint,
            index_name=env.get("VAHR_FLEET_INDEX", "").strip() or THING_INDEX,
            fleet_file=env.get("VAHR_FLEET_FILE", "").strip() or None,
            distances_file=env.get("VAHR_DISTANCES_FILE", "").strip() or BUNDLED_FILE,
            closed_task_days=days,
            log_level=level,
            audit_table=env.get("VAHR_AUDIT_TABLE", "").strip() or None,
            announcer_function=env.get("VAHR_ANNOUNCER_FUNCTION", "").strip() or None,
        )
