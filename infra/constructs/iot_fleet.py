"""The robots as IoT things (one per robot in fleet.yaml), their thing group, and the
experiment's own thing whose classic shadow holds the experiment state."""

from __future__ import annotations

from typing import TYPE_CHECKING

import aws_cdk as cdk
from aws_cdk import aws_iam as iam
from aws_cdk import aws_iot as iot
from aws_cdk import custom_resources as cr
from constructs import Construct

if TYPE_CHECKING:
    from aws_cdk import aws_logs as logs

    from vahr.domain import Fleet


def thing_arn(scope: Construct, thing: str) -> str:
    return cdk.Stack.of(scope).format_arn(service="iot", resource="thing", resource_name=thing)


class IotFleet(Construct):
    """Things for `fleet.robots`, the group `group_name` holding them, and the experiment thing."""

    def __init__(
        self,
        scope: Construct,
        construct_id: str,
        *,
        fleet: Fleet,
        group_name: str,
        provider_logs: logs.ILogGroup,
    ) -> None:
        super().__init__(scope, construct_id)
        self.thing_names = list(fleet.robot_things)
        self.experiment_thing_name = fleet.experiment_thing
        self.group = iot.CfnThingGroup(
            self,
            "Group",
            thing_group_name=group_name,
            thing_group_properties=iot.CfnThingGroup.ThingGroupPropertiesProperty(
                thing_group_description="VAHR robots (from fleet.yaml)",
            ),
        )
        self.group_arn = cdk.Stack.of(self).format_arn(
            service="iot", resource="thinggroup", resource_name=group_name
        )
        self.things: dict[str, iot.CfnThing] = {}
        for robot in fleet.robots:
            thing = iot.CfnThing(
                self,
                f"Robot-{robot.thing}",
                thing_name=robot.thing,
                attribute_payload=iot.CfnThing.AttributePayloadProperty(
                    attributes={"vahr_role": "robot"}
                ),
            )
            self.things[robot.thing] = thing
            self._add_to_group(robot.thing, thing, provider_logs)
        self.experiment_thing = iot.CfnThing(
            self,
            "ExperimentThing",
            thing_name=fleet.experiment_thing,
            attribute_payload=iot.CfnThing.AttributePayloadProperty(
                attributes={"vahr_role": "experiment"}
            ),
        )

    def _add_to_group(self, name: str, thing: iot.CfnThing, provider_logs: logs.ILogGroup) -> None:
        # CloudFormation has no thing-group membership resource; the IoT API call is made
        # on create and undone on delete, with rights on exactly this thing and group.
        parameters = {"thingName": name, "thingGroupName": self.group.thing_group_name}
        membership = cr.AwsCustomResource(
            self,
            f"Member-{name}",
            on_create=cr.AwsSdkCall(
                service="Iot",
                action="addThingToThingGroup",
                parameters=parameters,
                physical_resource_id=cr.PhysicalResourceId.of(
                    f"{name}@{self.group.thing_group_name}"
                ),
            ),
            on_delete=cr.AwsSdkCall(
                service="Iot",
                action="removeThingFromThingGroup",
                parameters=parameters,
                # Already gone (deleted by hand) must not block deleting the stack.
                ignore_error_codes_matching="ResourceNotFoundException",
            ),
            policy=cr.AwsCustomResourcePolicy.from_statements(
                [
                    iam.PolicyStatement(
                        actions=["iot:AddThingToThingGroup", "iot:RemoveThingFromThingGroup"],
                        resources=[thing_arn(self, name), self.group_arn],
                    )
                ]
            ),
            install_latest_aws_sdk=False,
            log_group=provider_logs,
        )
        membership.node.add_dependency(thing)
        membership.node.add_dependency(self.group)
