"""IoT things from fleet.yaml, the thing group, and the presence-to-shadow topic rule."""

from __future__ import annotations

import json
from typing import TYPE_CHECKING, Any

import aws_cdk as cdk
from aws_cdk import aws_logs as logs
from aws_cdk.assertions import Template
from template_tools import bare_stack, grants, only, resources, role_grants

from infra.constructs.iot_fleet import IotFleet
from infra.constructs.presence_rule import PresenceRule
from vahr.domain import Fleet

if TYPE_CHECKING:
    from pathlib import Path

PREFIX = "arn:aws:iot:us-east-1:123456789012"

THREE_ROBOTS = """
experiment_thing: lab-experiment
robots:
  - {thing: rover-a, spoken: [rover a], start: {x: 0, y: 0}}
  - {thing: rover-b, spoken: [rover b], start: {x: 1, y: 0}}
  - {thing: rover-c, spoken: [rover c], start: {x: 2, y: 0}}
zones:
  - {id: LOADING, spoken: [loading], pose: {x: 0, y: 1}}
"""


def synth_fleet(outdir: Path, fleet: Fleet) -> dict[str, Any]:
    stack = bare_stack(outdir)
    provider_logs = logs.LogGroup(stack, "ProviderLogs", removal_policy=cdk.RemovalPolicy.DESTROY)
    IotFleet(stack, "Fleet", fleet=fleet, group_name="vahr-robots", provider_logs=provider_logs)
    return Template.from_stack(stack).to_json()


def test_one_thing_per_robot_in_fleet_yaml_plus_the_experiment_thing(
    tmp_path: Path, fleet: Fleet
) -> None:
    # Given the repository's fleet.yaml
    template = synth_fleet(tmp_path, fleet)
    # Then the things are its robots and its experiment thing, nothing else
    things = {p["ThingName"]: p for p in resources(template, "AWS::IoT::Thing").values()}
    assert set(things) == {*fleet.robot_things, fleet.experiment_thing}
    assert set(things) == {"placebot1", "placebot2", "vahr-experiment"}
    assert things["placebot1"]["AttributePayload"] == {"Attributes": {"vahr_role": "robot"}}
    assert things["vahr-experiment"]["AttributePayload"] == {
        "Attributes": {"vahr_role": "experiment"}
    }
    assert only(template, "AWS::IoT::ThingGroup")["ThingGroupName"] == "vahr-robots"


def test_another_fleet_file_gives_other_things_and_group_members(tmp_path: Path) -> None:
    # Given a fleet of three robots and another experiment thing
    fleet = Fleet.from_yaml(THREE_ROBOTS)
    template = synth_fleet(tmp_path, fleet)
    # Then there is a thing for each, and each robot (not the experiment) joins the group
    names = {p["ThingName"] for p in resources(template, "AWS::IoT::Thing").values()}
    assert names == {"rover-a", "rover-b", "rover-c", "lab-experiment"}
    members = [json.loads(p["Create"]) for p in resources(template, "Custom::AWS").values()]
    assert sorted(m["parameters"]["thingName"] for m in members) == [
        "rover-a",
        "rover-b",
        "rover-c",
    ]
    assert {m["action"] for m in members} == {"addThingToThingGroup"}
    assert {m["parameters"]["thingGroupName"] for m in members} == {"vahr-robots"}
    # And each membership call may touch only its own thing and the group
    member_policies = [
        grants(p["PolicyDocument"])
        for p in resources(template, "AWS::IAM::Policy").values()
        if "Member" in p["PolicyName"]
    ]
    assert sorted(member_policies, key=str) == sorted(
        (
            {
                ("Allow", action, resource)
                for action in ("iot:AddThingToThingGroup", "iot:RemoveThingFromThingGroup")
                for resource in (f"{PREFIX}:thing/{thing}", f"{PREFIX}:thinggroup/vahr-robots")
            }
            for thing in ("rover-a", "rover-b", "rover-c")
        ),
        key=str,
    )


def test_presence_becomes_reported_connected_in_the_senders_shadow(
    tmp_path: Path, fleet: Fleet
) -> None:
    # Given the presence rule for the fleet
    stack = bare_stack(tmp_path)
    PresenceRule(stack, "Presence", rule_name="vahr_presence_to_shadow", things=fleet.robot_things)
    template = Template.from_stack(stack).to_json()
    payload = only(template, "AWS::IoT::TopicRule")["TopicRulePayload"]
    # Then it reads every robot's presence topic, keeps boolean `online` only, and writes
    # {"state": {"reported": {"connected": online}}} to the sender's classic shadow
    assert payload["Sql"] == (
        "SELECT {'reported': {'connected': online}} AS state "
        "FROM 'vahr/robots/+/presence' WHERE isBoolean(online)"
    )
    assert payload["AwsIotSqlVersion"] == "2016-03-23"
    assert payload["RuleDisabled"] is False
    [action] = payload["Actions"]
    assert action["Republish"]["Topic"] == "$$aws/things/${topic(3)}/shadow/update"
    assert action["Republish"]["Qos"] == 1
    # And its role may publish only to those robots' shadow update topics
    role_id = action["Republish"]["RoleArn"].strip("<>").split(".")[0]
    assert role_grants(template, role_id) == {
        ("Allow", "iot:Publish", f"{PREFIX}:topic/$aws/things/{thing}/shadow/update")
        for thing in ("placebot1", "placebot2")
    }
    role = resources(template, "AWS::IAM::Role")[role_id]
    assert role["AssumeRolePolicyDocument"]["Statement"][0]["Principal"] == {
        "Service": "iot.amazonaws.com"
    }
