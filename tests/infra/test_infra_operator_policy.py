"""The operator station's and the experiment recorder's IoT policies: each connects only under
its own client ids, commands and watches the fleet, and nothing more."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import pytest
from aws_cdk.assertions import Template
from iot_policy_eval import Connection, IotPolicy
from template_tools import bare_stack, resources

from infra.constructs.operator_policy import OperatorPolicy
from vahr.protocol import topics

if TYPE_CHECKING:
    from vahr.domain import Fleet


@pytest.fixture(scope="module")
def policies(tmp_path_factory: pytest.TempPathFactory, fleet: Fleet) -> dict[str, IotPolicy]:
    stack = bare_stack(tmp_path_factory.mktemp("operators"))
    for operator in ("station", "recorder"):
        OperatorPolicy(
            stack,
            operator.title(),
            operator=operator,  # type: ignore[arg-type]
            policy_name=f"vahr-{operator}-policy",
            things=fleet.robot_things,
        )
    found = resources(Template.from_stack(stack).to_json(), "AWS::IoT::Policy").values()
    documents: dict[str, dict[str, Any]] = {p["PolicyName"]: p["PolicyDocument"] for p in found}
    # Their certificates are attached to no thing.
    return {
        operator: IotPolicy(documents[f"vahr-{operator}-policy"], Connection(None))
        for operator in ("station", "recorder")
    }


@pytest.fixture(scope="module")
def station(policies: dict[str, IotPolicy]) -> IotPolicy:
    return policies["station"]


@pytest.fixture(scope="module")
def recorder(policies: dict[str, IotPolicy]) -> IotPolicy:
    return policies["recorder"]


def test_each_connects_only_under_its_own_client_ids(
    station: IotPolicy, recorder: IotPolicy, fleet: Fleet
) -> None:
    assert station.can_connect("vahr-station-0f3a9c2b11d4")
    assert recorder.can_connect("vahr-experiment-P01-vahr-trial1")
    # Not as each other: a station's certificate cannot take the recorder's session over
    assert not station.can_connect("vahr-experiment-P01-vahr-trial1")
    assert not recorder.can_connect("vahr-station-0f3a9c2b11d4")
    # Never as a robot (whose session it would take over), nor the experiment thing
    for policy in (station, recorder):
        for thing in fleet.robot_things:
            assert not policy.can_connect(thing)
        assert not policy.can_connect("vahr-experiment")
        assert not policy.can_connect("vahr-console-lab")


def test_both_command_the_fleet_and_watch_it(
    station: IotPolicy, recorder: IotPolicy, fleet: Fleet
) -> None:
    for policy in (station, recorder):
        for thing in fleet.robot_things:
            assert policy.can_publish(topics.robot_cmd(thing))
            assert policy.can_receive(topics.robot_events(thing))
            assert policy.can_receive(topics.robot_cmd(thing))
            assert policy.can_subscribe(topics.robot_cmd(thing))
        assert policy.can_publish(topics.FLEET_CMD)
        for topic_filter in (topics.ALL_EVENTS, topics.FLEET_CMD, topics.ALL_ROBOT_CMDS):
            assert policy.can_subscribe(topic_filter)
    # Presence is the station's to show; the recorder records commands and events only
    assert station.can_subscribe(topics.ALL_PRESENCE)
    assert station.can_receive(topics.robot_presence("placebot1"))
    assert not recorder.can_subscribe(topics.ALL_PRESENCE)


def test_neither_speaks_for_a_robot_nor_touches_shadows(
    station: IotPolicy, recorder: IotPolicy, fleet: Fleet
) -> None:
    for policy in (station, recorder):
        for thing in fleet.robot_things:
            assert not policy.can_publish(topics.robot_events(thing))
            assert not policy.can_publish(topics.robot_presence(thing), retain=True)
            assert not policy.can_publish(topics.shadow(thing, "update"))
            assert not policy.can_publish(topics.shadow(thing, "get"))
            assert not policy.can_subscribe(topics.shadow(thing, "update/delta"))
        # Commands to things outside the fleet are not theirs to send
        assert not policy.can_publish(topics.robot_cmd("intruder"))
        assert not policy.can_subscribe("#")
        assert not policy.can_subscribe(topics.shadow_filter())


def test_the_station_watches_the_fleets_shadow_documents_only(
    station: IotPolicy, recorder: IotPolicy, fleet: Fleet
) -> None:
    assert station.can_subscribe(topics.ALL_SHADOW_DOCUMENTS)
    for thing in fleet.robot_things:
        assert station.can_receive(topics.shadow(thing, "update/documents"))
        assert not recorder.can_receive(topics.shadow(thing, "update/documents"))
    assert not station.can_receive(topics.shadow(fleet.experiment_thing, "update/documents"))
    assert not station.can_receive(topics.shadow("intruder", "update/documents"))
    assert not recorder.can_subscribe(topics.ALL_SHADOW_DOCUMENTS)


def test_the_recorder_keeps_the_session_and_the_station_sends_the_input(
    station: IotPolicy, recorder: IotPolicy
) -> None:
    # The recorder keeps the session's status retained (and its will clears it)
    assert recorder.can_publish(topics.EXPERIMENT_STATUS, retain=True)
    assert station.can_subscribe(topics.EXPERIMENT_STATUS)
    assert station.can_receive(topics.EXPERIMENT_STATUS)
    assert not station.can_publish(topics.EXPERIMENT_STATUS)
    # The station sends the participant's input, which the recorder receives
    assert station.can_publish(topics.EXPERIMENT_INPUT)
    assert recorder.can_subscribe(topics.EXPERIMENT_INPUT)
    assert recorder.can_receive(topics.EXPERIMENT_INPUT)
    assert not recorder.can_publish(topics.EXPERIMENT_INPUT)
    # Nothing else is retained, and the assistant's turns are not theirs to send
    assert not station.can_publish(topics.EXPERIMENT_INPUT, retain=True)
    for policy in (station, recorder):
        assert not policy.can_publish(topics.ASSISTANT_TURNS)


def test_the_station_hears_the_assistants_announcements_and_nobody_makes_them(
    station: IotPolicy, recorder: IotPolicy
) -> None:
    assert station.can_subscribe(topics.ASSISTANT_ANNOUNCEMENTS)
    assert station.can_receive(topics.ASSISTANT_ANNOUNCEMENTS)
    assert not recorder.can_subscribe(topics.ASSISTANT_ANNOUNCEMENTS)
    for policy in (station, recorder):
        assert not policy.can_publish(topics.ASSISTANT_ANNOUNCEMENTS)
        assert not policy.can_publish(topics.ASSISTANT_ANNOUNCEMENTS, retain=True)
        assert not policy.can_subscribe("vahr/assistant/#")
