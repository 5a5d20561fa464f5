"""Context flags: parsed from cdk.json values or `-c key=value` strings, errors in one line."""

from __future__ import annotations

import json
import sys
from pathlib import Path
from typing import Any

import pytest
from template_tools import NO_ASK_STATES, SKILL_ID

from infra.config import REPO_ROOT, InfraConfig
from vahr.errors import VahrError


def config(**context: Any) -> InfraConfig:
    """The flags `context` (with any skill allowed, unless said otherwise: synth refuses
    an app that knows no skill id, tested apart)."""
    return InfraConfig.from_context(
        {"askStatesFile": NO_ASK_STATES, "allowAnySkill": "true", **context}.get
    )


def test_defaults_are_the_lean_deployment() -> None:
    defaults = config()
    assert (defaults.skill, defaults.lex, defaults.skill_id) == (False, False, None)
    assert (defaults.iot_logging, defaults.device_audit, defaults.alarm_email) == (True, True, None)
    assert (defaults.station_policy_name, defaults.recorder_policy_name) == (
        "vahr-station-policy",
        "vahr-recorder-policy",
    )
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
        ({"stationPolicyName": "a b"}, "stationPolicyName: 'a b' must be 1-64 letters"),
        ({"allowAnySkill": "perhaps"}, "allowAnySkill: 'perhaps' is not true or false"),
        ({"deviceDefenderAudit": "2"}, "deviceDefenderAudit: '2' is not true or false"),
        ({"alarmEmail": "ops"}, "alarmEmail: 'ops' is not an email address"),
        ({"operatorPolicyName": "x"}, "operatorPolicyName: the station and the recorder now"),
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


def ask_states(tmp_path: Path, profiles: object) -> str:
    states = tmp_path / "ask-states.json"
    states.write_text(json.dumps({"askcliStatesVersion": "2020-03-31", "profiles": profiles}))
    return str(states)


def test_after_ask_deploy_the_skill_id_comes_from_its_state_file(tmp_path: Path) -> None:
    # Given `ask deploy` recorded the skill id for the default profile
    states = ask_states(tmp_path, {"default": {"skillId": SKILL_ID, "skillMetadata": {}}})
    # Then the next synth locks the function to that skill without -c skillId
    assert config(askStatesFile=states).skill_id == SKILL_ID
    # And an explicit skillId still wins; another ASK profile is read when named
    other = SKILL_ID.replace("0d5c", "1e6d")
    assert config(askStatesFile=states, skillId=other).skill_id == other
    assert config(askStatesFile=states, askProfile="lab").skill_id is None


def test_a_broken_ask_state_file_is_reported_in_one_line(tmp_path: Path) -> None:
    broken = tmp_path / "ask-states.json"
    broken.write_text("{")
    with pytest.raises(VahrError, match=r"ask-states\.json: cannot read the ASK CLI's state"):
        config(askStatesFile=str(broken))
    bad_id = ask_states(tmp_path, {"default": {"skillId": "nope"}})
    with pytest.raises(VahrError, match=r"^skillId: 'nope' is not an Alexa skill id"):
        config(askStatesFile=bad_id)


def test_a_stack_that_knows_no_skill_id_is_refused_in_one_line_naming_the_flag() -> None:
    # Given no skill id (none given, no `ask deploy` state), no skill in the stack, and
    # nothing said about the risk
    with pytest.raises(VahrError) as raised:
        config(allowAnySkill=None)
    # Then synth stops, naming the flag that would accept the risk
    assert str(raised.value) == (
        "skillId: none is known, so any Alexa skill could invoke the skill function; give "
        "-c skillId=amzn1.ask.skill... (ask deploy prints it), create the skill with the "
        "stack (-c skill=true), or accept that risk with -c allowAnySkill=true"
    )
    # And each of the three ways out is accepted
    assert config(allowAnySkill=None, skillId=SKILL_ID).skill_invocation() == "skill_id"
    assert config(allowAnySkill=None, skill="true").skill_invocation() == "stack_skill"
    assert config(allowAnySkill="true").skill_invocation() == "any_skill"


def test_what_lets_aws_see_trouble_can_be_left_to_another_stack() -> None:
    chosen = config(iotLogging="false", deviceDefenderAudit="false", alarmEmail="ops@lab.example")
    assert (chosen.iot_logging, chosen.device_audit) == (False, False)
    assert chosen.alarm_email == "ops@lab.example"
