"""The operator IoT policy (experiment recorder, console): command and watch, nothing more."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import pytest
from aws_cdk.assertions import Template
from iot_policy_eval import Connection, IotPolicy
from template_tools import bare_stack, only

from infra.constructs.operator_policy import OperatorPolicy
from vahr.protocol import topics

if TYPE_CHECKING:
    from vahr.domain import Fleet


@pytest.fixture(scope="module")
def operator(tmp_path_factory: pytest.TempPathFactory, fleet: Fleet) -> IotPolicy:
    stack = bare_stack(tmp_path_factory.mktemp("operator"))
    OperatorPolicy(stack, "Operator", policy_name="vahr-operator-policy", things=fleet.robot_things)
    policy = only(Template.from_stack(stack).to_json(), "AWS::IoT::Policy")
    assert policy["PolicyName"] == "vahr-operator-policy"
    document: dict[str, Any] = policy["PolicyDocument"]
    # Operators' certificates are attached to no thing.
    return IotPolicy(document, Connection(None))


def test_the_recorder_and_console_connect_under_their_own_client_ids(operator: IotPolicy) -> None:
    assert operator.can_connect("vahr-experiment-P01-vahr-trial1")
    assert operator.can_connect("vahr-console-lab")
    assert operator.can_connect("vahr-station-0f3a9c2b11d4")
    # Never as a robot: that would take over the robot's session
    assert not operator.can_connect("placebot1")
    assert not operator.can_connect("vahr-experiment")  # the experiment thing's name


def test_the_console_commands_the_fleet_and_watches_it(operator: IotPolicy, fleet: Fleet) -> None:
    for thing in fleet.robot_things:
        assert operator.can_publish(topics.robot_cmd(thing))
        assert operator.can_receive(topics.robot_events(thing))
        assert operator.can_receive(topics.robot_presence(thing))
        assert operator.can_receive(topics.robot_cmd(thing))
    assert operator.can_publish(topics.FLEET_CMD)
    for topic_filter in (topics.ALL_EVENTS, topics.ALL_PRESENCE, topics.FLEET_CMD):
        assert operator.can_subscribe(topic_filter)
    for thing in fleet.robot_things:
        assert operator.can_subscribe(topics.robot_cmd(thing))


def test_the_console_cannot_speak_for_a_robot_or_touch_shadows(
    operator: IotPolicy, fleet: Fleet
) -> None:
    for thing in fleet.robot_things:
        assert not operator.can_publish(topics.robot_events(thing))
        assert not operator.can_publish(topics.robot_presence(thing), retain=True)
        assert not operator.can_publish(topics.shadow(thing, "update"))
        assert not operator.can_subscribe(topics.shadow(thing, "update/delta"))
    # Commands to things outside the fleet are not the console's to send
    assert not operator.can_publish(topics.robot_cmd("intruder"))
    assert not operator.can_subscribe("#")


def test_the_station_watches_shadow_documents_and_wildcard_commands_of_the_fleet_only(
    operator: IotPolicy, fleet: Fleet
) -> None:
    # The station subscribes with MQTT wildcards, as the recorder does
    assert operator.can_subscribe(topics.ALL_SHADOW_DOCUMENTS)
    assert operator.can_subscribe(topics.ALL_ROBOT_CMDS)
    for thing in fleet.robot_things:
        assert operator.can_receive(topics.shadow(thing, "update/documents"))
    # but receives the documents of the fleet's robots only, and changes no shadow
    assert not operator.can_receive(topics.shadow(fleet.experiment_thing, "update/documents"))
    assert not operator.can_receive(topics.shadow("intruder", "update/documents"))
    for thing in fleet.robot_things:
        assert not operator.can_publish(topics.shadow(thing, "get"))
        assert not operator.can_publish(topics.shadow(thing, "update"))
    assert not operator.can_subscribe(topics.shadow_filter())


def test_the_recorder_and_the_station_share_the_session(operator: IotPolicy) -> None:
    # The recorder keeps the session's status retained (and its will clears it)
    assert operator.can_publish(topics.EXPERIMENT_STATUS, retain=True)
    assert operator.can_subscribe(topics.EXPERIMENT_STATUS)
    assert operator.can_receive(topics.EXPERIMENT_STATUS)
    # The station sends the participant's input, which the recorder receives
    assert operator.can_publish(topics.EXPERIMENT_INPUT)
    assert operator.can_subscribe(topics.EXPERIMENT_INPUT)
    assert operator.can_receive(topics.EXPERIMENT_INPUT)
    # Nothing else is retained, and the assistant's turns are not the operators' to send
    assert not operator.can_publish(topics.EXPERIMENT_INPUT, retain=True)
    assert not operator.can_publish(topics.ASSISTANT_TURNS)


def test_the_station_hears_the_assistants_announcements_and_cannot_make_them(
    operator: IotPolicy,
) -> None:
    # The announcer function publishes them on AWS; the station subscribes and receives
    assert operator.can_subscribe(topics.ASSISTANT_ANNOUNCEMENTS)
    assert operator.can_receive(topics.ASSISTANT_ANNOUNCEMENTS)
    # but nobody on the people's side speaks for the assistant
    assert not operator.can_publish(topics.ASSISTANT_ANNOUNCEMENTS)
    assert not operator.can_publish(topics.ASSISTANT_ANNOUNCEMENTS, retain=True)
    assert not operator.can_subscribe("vahr/assistant/#")
