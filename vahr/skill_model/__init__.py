"""The skill package generator: `python -m vahr.skill_model [--check]`.

It writes `skill-package/` (skill.json and the en-US interaction model) from `fleet.yaml`
and the intent definitions kept as data in `vahr.skill_model.intents`, so the ROBOT and
ZONE slot types never drift from the fleet.
"""

from __future__ import annotations

from vahr.skill_model.generator import (
    FLEET_ROBOT_ID,
    ModelError,
    build_files,
    build_interaction_model,
    drift,
    write,
)

__all__ = [
    "FLEET_ROBOT_ID",
    "ModelError",
    "build_files",
    "build_interaction_model",
    "drift",
    "write",
]
