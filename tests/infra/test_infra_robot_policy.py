"""The robot IoT policy: each robot may do exactly its own part and nothing of its peers'."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import pytest
from aws_cdk.assertions import Template
from iot_policy_eval import Connection, IotPolicy
from template_tools import bare_stack, grants, only

from infra.constructs.robot_policy import RobotPolicy
from vahr.protocol import topics

if TYPE_CHECKING:
    from pathlib import Path

    from vahr.domain import Fleet

PREFIX = "arn:aws:iot:us-east-1:123456789012"
ROLE_ALIAS_ARN = f"{PREFIX}:rolealias/vahr-robot-lex"
SHADOW_RESPONSES = [op for op in topics.SHADOW_OPERATIONS if op not in ("update", "get", "delete")]


def synth_policy(outdir: Path, role_alias_arn: str | None = None) -> dict[str, Any]:
    stack = bare_stack(outdir)
    RobotPolicy(
        stack, "RobotPolicy", policy_name="vahr-robot-policy", role_alias_arn=role_alias_arn
    )
    policy = only(Template.from_stack(stack).to_json(), "AWS::IoT::Policy")
    assert policy["PolicyName"] == "vahr-robot-policy"
    document: dict[str, Any] = policy["PolicyDocument"]
    return document


@pytest.fixture(scope="module")
def document(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Any]:
    return synth_policy(tmp_path_factory.mktemp("policy"))


def test_the_policy_states_exactly_the_robot_rights(document: dict[str, Any]) -> None:
    # Given the synthesized robot policy
    # When its statements are listed as (effect, action, resource)
    stated = grants(document)
    # Then they are exactly these, all Allow, no more
    me = "${iot:Connection.Thing.ThingName}"
    listen = [
        f"vahr/robots/{me}/cmd", "vahr/fleet/cmd", "vahr/fleet/zones", "vahr/robots/*/events",
        "vahr/robots/*/presence", *(f"$aws/things/{me}/shadow/{op}" for op in SHADOW_RESPONSES),
    ]  # fmt: skip
    expected = {
        ("Allow", "iot:Connect", f"{PREFIX}:client/{me}"),
        *(("Allow", "iot:Publish", f"{PREFIX}:topic/{t}") for t in [
            f"vahr/robots/{me}/events", f"vahr/robots/{me}/presence",
            f"$aws/things/{me}/shadow/update", f"$aws/things/{me}/shadow/get",
            f"$aws/things/{me}/shadow/delete",
        ]),
        ("Allow", "iot:RetainPublish", f"{PREFIX}:topic/vahr/robots/{me}/events"),
        ("Allow", "iot:RetainPublish", f"{PREFIX}:topic/vahr/robots/{me}/presence"),
        *(("Allow", "iot:Subscribe", f"{PREFIX}:topicfilter/{t}") for t in listen),
        *(("Allow", "iot:Receive", f"{PREFIX}:topic/{t}") for t in listen),
    }  # fmt: skip
    assert stated == expected
    connect = next(s for s in document["Statement"] if s["Action"] == "iot:Connect")
    assert connect["Condition"] == {"Bool": {"iot:Connection.Thing.IsAttached": "true"}}


def test_a_robot_connects_only_as_its_own_attached_thing(document: dict[str, Any]) -> None:
    # Given placebot1's certificate attached to thing placebot1
    placebot1 = IotPolicy(document, Connection("placebot1"))
    # Then it may connect with client id placebot1 and no other
    assert placebot1.can_connect("placebot1")
    assert not placebot1.can_connect("placebot2")
    assert not placebot1.can_connect("vahr-experiment")
    assert not placebot1.can_connect("*")
    # And a certificate attached to no thing may not connect at all
    assert not IotPolicy(document, Connection(None)).can_connect("placebot1")


@pytest.mark.parametrize(("me", "peer"), [("placebot1", "placebot2"), ("placebot2", "placebot1")])
def test_a_robot_uses_its_own_topics_and_is_denied_its_peers(
    document: dict[str, Any], me: str, peer: str
) -> None:
    robot = IotPolicy(document, Connection(me))
    # Its own commands and the fleet's: subscribe and receive, never send
    for topic in (topics.robot_cmd(me), topics.FLEET_CMD):
        assert robot.can_subscribe(topic) and robot.can_receive(topic)
        assert not robot.can_publish(topic)
    # The peer's commands: nothing at all
    assert not robot.can_subscribe(topics.robot_cmd(peer))
    assert not robot.can_receive(topics.robot_cmd(peer))
    assert not robot.can_publish(topics.robot_cmd(peer))
    # Its own events and presence, also retained: publish; the peer's: read only
    assert robot.can_publish(topics.robot_events(me), retain=True)
    assert robot.can_publish(topics.robot_presence(me), retain=True)
    assert not robot.can_publish(topics.robot_events(peer))
    assert not robot.can_publish(topics.robot_events(peer), retain=True)
    assert not robot.can_publish(topics.robot_presence(peer), retain=True)
    # Retaining is for its events and presence only, not for shadow requests
    assert not robot.can_publish(topics.shadow(me, "update"), retain=True)
    for topic in (topics.robot_events(peer), topics.robot_presence(peer)):
        assert robot.can_subscribe(topic) and robot.can_receive(topic)
    assert robot.can_subscribe(topics.ALL_EVENTS) and robot.can_subscribe(topics.ALL_PRESENCE)
    # Its own classic shadow: requests out, answers in
    for op in ("update", "get", "delete"):
        assert robot.can_publish(topics.shadow(me, op))
        assert not robot.can_publish(topics.shadow(peer, op))
    for op in SHADOW_RESPONSES:
        assert robot.can_subscribe(topics.shadow(me, op)) and robot.can_receive(
            topics.shadow(me, op)
        )
        assert not robot.can_subscribe(topics.shadow(peer, op))
        assert not robot.can_receive(topics.shadow(peer, op))
    # Named shadows and the experiment thing's shadow are not the robot's
    assert not robot.can_publish(topics.shadow(me, "update", name="extra"))
    assert not robot.can_publish(topics.shadow("vahr-experiment", "update"))
    assert not robot.can_receive(topics.shadow("vahr-experiment", "update/accepted"))


@pytest.mark.parametrize(
    "topic_filter",
    ["#", "vahr/#", "vahr/robots/#", "vahr/robots/+/cmd", "vahr/robots/+/+", "$aws/things/+/shadow/update/delta",
     "$aws/things/placebot2/shadow/#", "$aws/things/placebot1/shadow/#", "$aws/events/presence/connected/+"],
)  # fmt: skip
def test_wildcard_subscriptions_that_reach_beyond_the_robot_are_denied(
    document: dict[str, Any], topic_filter: str
) -> None:
    assert not IotPolicy(document, Connection("placebot1")).can_subscribe(topic_filter)


def test_every_fleet_robot_is_isolated_from_every_other(
    document: dict[str, Any], fleet: Fleet
) -> None:
    # Given every ordered pair of distinct robots in fleet.yaml
    for me in fleet.robot_things:
        robot = IotPolicy(document, Connection(me))
        for peer in fleet.robot_things:
            if peer == me:
                continue
            # Then the robot cannot command, impersonate or read the shadow of its peer
            assert not robot.can_connect(peer)
            assert not robot.can_receive(topics.robot_cmd(peer))
            assert not robot.can_publish(topics.robot_events(peer))
            assert not robot.can_publish(topics.shadow(peer, "update"))
            assert not robot.can_receive(topics.shadow(peer, "update/delta"))


def test_no_data_plane_or_control_plane_actions_for_robots(document: dict[str, Any]) -> None:
    robot = IotPolicy(document, Connection("placebot1"))
    for action in ("iot:GetThingShadow", "iot:UpdateThingShadow", "iot:DeleteThingShadow"):
        assert not robot.allows(action, f"{PREFIX}:thing/placebot1")
    assert not robot.allows("iot:AssumeRoleWithCertificate", ROLE_ALIAS_ARN)


def test_with_the_lex_role_alias_the_robot_may_exchange_its_certificate(tmp_path: Path) -> None:
    # Given the policy built for a stack with the Lex bot
    document = synth_policy(tmp_path, role_alias_arn=ROLE_ALIAS_ARN)
    robot = IotPolicy(document, Connection("placebot1"))
    # Then exactly one more right: that role alias, no other
    assert robot.allows("iot:AssumeRoleWithCertificate", ROLE_ALIAS_ARN)
    assert not robot.allows("iot:AssumeRoleWithCertificate", f"{PREFIX}:rolealias/other")
    extra = {g for g in grants(document) if g[1] == "iot:AssumeRoleWithCertificate"}
    assert extra == {("Allow", "iot:AssumeRoleWithCertificate", ROLE_ALIAS_ARN)}
