"""Context flags: parsed from cdk.json values or `-c key=value` strings, errors in one line."""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Any

import pytest

from infra.config import REPO_ROOT, InfraConfig
from vahr.errors import VahrError


def config(**context: Any) -> InfraConfig:
    return InfraConfig.from_context(context.get)


def test_defaults_are_the_lean_deployment() -> None:
    defaults = config()
    assert (defaults.skill, defaults.lex, defaults.skill_id) == (False, False, None)
    assert defaults.fleet_file == REPO_ROOT / "fleet.yaml"
    assert defaults.robot_policy_name == "vahr-robot-policy"
    assert defaults.architecture == "x86_64"


@pytest.mark.parametrize(("raw", "expected"), [(True, True), ("true", True), ("1", True), ("false", False), (False, False), ("off", False)])  # fmt: skip
def test_flags_read_json_booleans_and_command_line_strings(raw: Any, expected: bool) -> None:
    assert config(skill=raw, lex=raw).skill is expected


def test_relative_paths_are_from_the_repository_root() -> None:
    assert config(fleetFile="lab/fleet.yaml").fleet_file == REPO_ROOT / "lab" / "fleet.yaml"


@pytest.mark.parametrize(
    ("context", "message"),
    [
        ({"skill": "maybe"}, "skill: 'maybe' is not true or false"),
        ({"skillId": "my-skill"}, "skillId: 'my-skill' is not an Alexa skill id"),
        ({"architecture": "mips"}, "architecture: 'mips' must be x86_64 or arm64"),
        ({"logRetentionDays": "10"}, "logRetentionDays: 10 is not a CloudWatch Logs retention"),
        ({"ackTimeoutS": "7"}, "ackTimeoutS: 7 must be in (0, 6]"),
        ({"ackTimeoutS": "soon"}, "ackTimeoutS: 'soon' is not a number"),
        ({"logLevel": "chatty"}, "logLevel: 'CHATTY' must be DEBUG, INFO, WARNING or ERROR"),
        ({"robotPolicyName": "a/b"}, "robotPolicyName: 'a/b' must be 1-64 letters"),
    ],
)
def test_bad_values_are_refused_with_the_key_and_the_reason(
    context: dict[str, Any], message: str
) -> None:
    with pytest.raises(VahrError) as raised:
        config(**context)
    assert str(raised.value).startswith(message)
    assert "\n" not in str(raised.value)


def test_lambda_python_must_exist(tmp_path: Path) -> None:
    with pytest.raises(VahrError, match=r"^lambdaPython: '.*missing' is not a file$"):
        config(lambdaPython=str(tmp_path / "missing"))
    assert config(lambdaPython=sys.executable).lambda_python == Path(sys.executable)
