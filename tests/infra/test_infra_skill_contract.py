"""The skill handler, as built, stays inside the IAM rights the stack gives its function.

Every real-shaped Alexa request under tests/events/ runs through the real handler and its
boto3 iot-data adapter against moto; each iot-data call it makes is then checked against
the synthesized role policy. A call outside it would fail on AWS with AccessDenied.
"""

from __future__ import annotations

import json
from typing import TYPE_CHECKING, Any

import boto3
import pytest
from aws_cdk.assertions import Template
from iot_policy_eval import Connection, IotPolicy
from moto import mock_aws
from template_tools import ACCOUNT, REGION, REPO_ROOT, SKILL_ID, bare_stack, only, resources

from infra.config import InfraConfig
from infra.constructs.skill_function import SkillFunction
from skill.app import make_lambda_handler
from skill.config import SkillConfig
from skill.iot_data import IotDataGateway

if TYPE_CHECKING:
    from collections.abc import Iterator

    from vahr.domain import Fleet

EVENTS = sorted((REPO_ROOT / "tests" / "events").glob("alexa_*.json"))
PREFIX = f"arn:aws:iot:{REGION}:{ACCOUNT}"
# iot-data operation -> the IAM action AWS checks for it.
ACTIONS = {
    "Publish": "iot:Publish",
    "GetThingShadow": "iot:GetThingShadow",
    "UpdateThingShadow": "iot:UpdateThingShadow",
    "DeleteThingShadow": "iot:DeleteThingShadow",
    "ListNamedShadowsForThing": "iot:ListNamedShadowsForThing",
    "GetRetainedMessage": "iot:GetRetainedMessage",
}


@pytest.fixture(scope="module")
def role_policy(tmp_path_factory: pytest.TempPathFactory, fleet: Fleet) -> IotPolicy:
    stack = bare_stack(tmp_path_factory.mktemp("skill-contract"))
    SkillFunction(
        stack,
        "Skill",
        config=InfraConfig(skill_id=SKILL_ID),
        fleet=fleet,
        data_endpoint="example",
    )
    template = Template.from_stack(stack).to_json()
    role_id = only(template, "AWS::Lambda::Function")["Role"].strip("<>").split(".")[0]
    statements = [
        statement
        for policy in resources(template, "AWS::IAM::Policy").values()
        if f"<{role_id}>" in policy["Roles"]
        for statement in policy["PolicyDocument"]["Statement"]
    ]
    # An IAM policy has no connection variables: evaluate it as a plain document.
    return IotPolicy({"Statement": statements}, Connection(None, arn_prefix=PREFIX))


@pytest.fixture
def recorded_calls(
    monkeypatch: pytest.MonkeyPatch, fleet: Fleet
) -> Iterator[list[tuple[str, str]]]:
    """Run every event through the handler; yield (IAM action, resource ARN) per call."""
    for name in ("AWS_ENDPOINT_URL", "AWS_ENDPOINT_URL_IOT_DATA_PLANE", "AWS_PROFILE"):
        monkeypatch.delenv(name, raising=False)
    monkeypatch.setenv("AWS_DEFAULT_REGION", REGION)
    monkeypatch.setenv("AWS_ACCESS_KEY_ID", "testing")
    monkeypatch.setenv("AWS_SECRET_ACCESS_KEY", "testing")
    calls: list[tuple[str, str]] = []

    def record(model: Any, params: dict[str, Any], **_: Any) -> None:
        if model.name == "Publish":
            calls.append((ACTIONS["Publish"], f"{PREFIX}:topic/{params['topic']}"))
            return
        thing = params.get("thingName", "")
        shadow = f"/{params['shadowName']}" if params.get("shadowName") else ""
        calls.append(
            (ACTIONS.get(model.name, f"iot:{model.name}"), f"{PREFIX}:thing/{thing}{shadow}")
        )

    with mock_aws():
        iot = boto3.client("iot", region_name=REGION)
        for thing in (*fleet.robot_things, fleet.experiment_thing):
            iot.create_thing(thingName=thing)
        client = boto3.client("iot-data", region_name=REGION)
        client.meta.events.register("provide-client-params.iot-data.*", record)
        handler = make_lambda_handler(SkillConfig(ack_timeout_s=0.1), IotDataGateway(client))
        for event in EVENTS:
            handler(json.loads(event.read_text()), None)
        yield calls


def test_every_iot_data_call_of_every_request_is_allowed(
    role_policy: IotPolicy, recorded_calls: list[tuple[str, str]]
) -> None:
    # Given every Alexa request the skill handles (navigate, deliver, fleet, status, weather...)
    assert len(EVENTS) >= 10
    # Then it published commands and read shadows, and every call is within its rights
    actions = {action for action, _ in recorded_calls}
    assert {"iot:Publish", "iot:GetThingShadow"} <= actions
    denied = sorted({call for call in recorded_calls if not role_policy.allows(*call)})
    assert denied == []
    # And every IoT right it has is one of these requests uses: nothing to spare
    used = set(recorded_calls)
    granted = {
        (action, resource)
        for statement in role_policy.statements
        for action in (
            [statement["Action"]] if isinstance(statement["Action"], str) else statement["Action"]
        )
        if action.startswith("iot:")
        for resource in (
            [statement["Resource"]]
            if isinstance(statement["Resource"], str)
            else statement["Resource"]
        )
    }
    assert granted == used
