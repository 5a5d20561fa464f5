"""Load the skill's Lambda handler in-process, configured for the local data plane.

The skill (`lambda/skill` in the repository) is installed with the package as `skill`,
the name Lambda imports it by too.
"""

from __future__ import annotations

import os
from typing import Any

from vahr.errors import VahrError

SkillHandler = Any


def load_skill_handler(
    api_url: str,
    *,
    ack_timeout_s: float | None = None,
    skill_id: str | None = None,
    fleet_file: str | None = None,
    log_level: str = "WARNING",
    users_file: str | None = None,
    confirm: bool | None = None,
    audit_table: str | None = None,
) -> SkillHandler:
    """`skill.app`'s handler built around the local data plane (the same handler function
    Lambda runs, given another configuration): the people of `users_file`, fleet-wide
    commands confirmed as `confirm` says."""
    # The local data plane accepts any SigV4 signature, but boto3 will not sign without
    # credentials: give it dummy ones when the environment has none.
    if not (os.environ.get("AWS_ACCESS_KEY_ID") or os.environ.get("AWS_PROFILE")):
        os.environ["AWS_ACCESS_KEY_ID"] = "vahr-local"
        os.environ["AWS_SECRET_ACCESS_KEY"] = "vahr-local"
    try:
        from skill.app import make_lambda_handler
        from skill.config import SkillConfig
    except ImportError as err:
        raise VahrError(f"the skill handler cannot be imported ({err}): reinstall vahr") from err
    settings: dict[str, Any] = {
        "data_endpoint": api_url,
        "skill_id": skill_id,
        "fleet_file": fleet_file,
        "log_level": log_level,
        "users_file": users_file,
        "confirm": confirm,
        "audit_table": audit_table,
    }
    if ack_timeout_s is not None:
        settings["ack_timeout_s"] = ack_timeout_s
    return make_lambda_handler(SkillConfig(**settings))
