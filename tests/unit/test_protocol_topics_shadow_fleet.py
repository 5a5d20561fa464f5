"""Topic builders, the reported shadow document and the fleet model."""

from __future__ import annotations

import json

import pytest

from vahr.domain import load_fleet
from vahr.domain.fleet import Fleet, Pose
from vahr.protocol import (
    ExperimentState,
    LastCommand,
    ProtocolError,
    Reported,
    ReportedPose,
    experiment_state_from_payload,
    robot_shadow_from_payload,
    topics,
)


def test_topics_match_the_contract() -> None:
    assert topics.robot_cmd("placebot1") == "vahr/robots/placebot1/cmd"
    assert topics.FLEET_CMD == "vahr/fleet/cmd"
    assert topics.robot_events("placebot2") == "vahr/robots/placebot2/events"
    assert topics.robot_presence("placebot1") == "vahr/robots/placebot1/presence"
    assert topics.shadow("placebot1", "update") == "$aws/things/placebot1/shadow/update"
    assert (
        topics.shadow("placebot1", "get/accepted", name="voice")
        == "$aws/things/placebot1/shadow/name/voice/get/accepted"
    )


@pytest.mark.parametrize("thing", ["", "a/b", "+", "#", "robot one", "x" * 129])
def test_topic_builders_refuse_names_that_would_change_the_topic(thing: str) -> None:
    with pytest.raises(ValueError, match="thing"):
        topics.robot_cmd(thing)


def test_topics_parse_back() -> None:
    assert topics.parse_robot_topic("vahr/robots/placebot1/events") == ("placebot1", "events")
    assert topics.parse_robot_topic("vahr/fleet/cmd") is None
    assert topics.parse_shadow_topic("$aws/things/p1/shadow/name/n1/update/delta") == (
        "p1",
        "n1",
        "update/delta",
    )
    assert topics.parse_shadow_topic("$aws/things/p1/shadow/get") == ("p1", None, "get")
    assert topics.parse_shadow_topic("$aws/things/p1/shadow/bogus") is None


def test_reported_state_round_trips_through_a_shadow_document() -> None:
    state = Reported(
        status="navigating",
        zone=None,
        cargo=True,
        last_command=LastCommand(id="c-1", action="deliver", result="accepted"),
        connected=True,
        destination="B",
        task="deliver",
        pose=ReportedPose(x=1.0, y=2.0, theta=0.5),
    )
    body = json.loads(state.to_payload(client_token="t-1"))
    assert body["clientToken"] == "t-1"
    reported = body["state"]["reported"]
    assert {"status", "zone", "cargo", "last_command", "connected"} <= reported.keys()
    # Every field of the last command is sent, null included (a shadow merge deletes it).
    assert reported["last_command"] == {
        "id": "c-1", "action": "deliver", "result": "accepted", "reason": None, "zone": None,
    }  # fmt: skip
    document = {"state": {"reported": reported}, "metadata": {}, "version": 7, "timestamp": 1}
    shadow = robot_shadow_from_payload(json.dumps(document).encode())
    assert shadow.reported == state
    assert shadow.version == 7


def test_a_partial_shadow_reads_with_defaults() -> None:
    shadow = robot_shadow_from_payload(b'{"state":{"reported":{"connected":false}},"version":1}')
    assert shadow.reported.status == "idle"
    assert shadow.reported.connected is False
    assert shadow.reported.last_command is None


def test_a_shadow_with_a_bad_status_is_a_protocol_error() -> None:
    with pytest.raises(ProtocolError, match=r"^state\.reported\.status: "):
        robot_shadow_from_payload(b'{"state":{"reported":{"status":"flying"}}}')


def test_experiment_state_round_trips() -> None:
    state = ExperimentState(weather="rainy", assignments={"placebot1": "B"}, session="s1")
    assert experiment_state_from_payload(state.to_payload()) == state
    assert experiment_state_from_payload(b'{"state":{}}') == ExperimentState()


def test_the_default_fleet_is_the_papers(fleet: Fleet) -> None:
    assert fleet.robot_things == ("placebot1", "placebot2")
    assert set(fleet.zone_ids) == {"A", "B", "C", "D", "LOADING"}
    assert fleet.groups[0].robots == ["placebot1", "placebot2"]
    assert fleet.zone("LOADING").arm == "loader"
    assert fleet.zone_at(Pose(x=9.1, y=7.0)) == fleet.zone("A")
    assert fleet.zone_at(Pose(x=5.0, y=5.0)) is None
    assert fleet.spoken_name("placebot2") == "placebot two"


@pytest.mark.parametrize(
    ("text", "field"),
    [
        ("robots: []\nzones: []\n", "robots"),
        (
            "robots: [{thing: a/b, spoken: [x], start: {x: 0, y: 0}}]\nzones: [{id: LOADING, spoken: [l], pose: {x: 0, y: 0}}]\n",
            "robots.0.thing",
        ),
        (
            "robots: [{thing: r, spoken: [x], start: {x: 0, y: 0}}]\nzones: [{id: A, spoken: [a], pose: {x: 0, y: 0}}]\n",
            "zones",
        ),
        (
            "robots: [{thing: r, spoken: [], start: {x: 0, y: 0}}]\nzones: [{id: LOADING, spoken: [l], pose: {x: 0, y: 0}}]\n",
            "robots.0.spoken",
        ),
        (
            "robots: [{thing: r, spoken: [x], start: {x: 0, y: 0}}, {thing: r, spoken: [y], start: {x: 0, y: 0}}]\nzones: [{id: LOADING, spoken: [l], pose: {x: 0, y: 0}}]\n",
            "robots.1.thing",
        ),
        (
            "robots: [{thing: r, spoken: [x], start: {x: 0, y: 0}}]\nzones: [{id: LOADING, spoken: [l], pose: {x: 0, y: 0}}]\ngroups: [{id: g, spoken: [g], robots: [q]}]\n",
            "groups.0.robots.0",
        ),
        (
            "robots: [{thing: r, spoken: [x], start: {x: zero, y: 0}}]\nzones: [{id: LOADING, spoken: [l], pose: {x: 0, y: 0}}]\n",
            "robots.0.start.x",
        ),
        (
            "robots: [{thing: r, spoken: [x], start: {x: 0, y: 0}}]\nzones: [{id: LOADING, spoken: [l], pose: {x: 0, y: 0}}]\nfloor: {width: 0, height: 4}\n",
            "floor.width",
        ),
        (
            "robots: [{thing: r, spoken: [x], start: {x: 0, y: 0}}]\nzones: [{id: LOADING, spoken: [l], pose: {x: 0, y: 0}}]\nfloor: {width: 5, height: 4, arms: {B: {x: 1, y: 1}}}\n",
            "floor.arms",
        ),
        (
            "robots: [{thing: r, spoken: [x], start: {x: 0, y: 0}}]\nzones: [{id: LOADING, spoken: [l], pose: {x: 0, y: 0}}]\nfloor: {width: 5, height: 4, doors: []}\n",
            "floor.doors",
        ),
        ("robots: {", "fleet"),
        ("just a string", "fleet"),
    ],
)
def test_a_broken_fleet_file_names_the_field(text: str, field: str) -> None:
    with pytest.raises(ProtocolError) as raised:
        Fleet.from_yaml(text)
    assert raised.value.field == field, str(raised.value)


def test_the_default_fleet_draws_the_papers_floor(fleet: Fleet) -> None:
    # Given the bundled fleet.yaml, when the station asks for the floor to draw
    floor = fleet.layout()
    # Then it is the paper's warehouse: the room, the conveyor, an arm per zone, the LED
    assert (floor.width, floor.height) == (10.5, 8.0)
    assert floor.conveyor is not None and floor.led is not None
    assert set(floor.arms) == set(fleet.zone_ids)
    assert len(floor.walls) >= 4


def test_a_fleet_file_without_a_floor_still_loads_and_gets_one_around_it() -> None:
    # Given a fleet file written before the floor existed
    fleet = Fleet.from_yaml(
        "robots: [{thing: r, spoken: [x], start: {x: -2, y: 1}}]\n"
        "zones: [{id: LOADING, spoken: [l], pose: {x: 3, y: 1}, arm: loader},"
        " {id: A, spoken: [a], pose: {x: 6, y: 5, theta: 1.5708}, arm: unloader}]\n"
    )
    # When the floor is asked for
    floor = fleet.layout()
    # Then it surrounds every zone and start pose with a margin, walled all round
    assert floor.origin.x == -3.0 and floor.origin.y == -0.5
    assert floor.width == 10.5 and floor.height == 7.0
    assert len(floor.walls) == 4
    # and each arm stands ahead of its zone, along the zone's heading
    assert floor.arms["A"].x == 6.0 and floor.arms["A"].y == 5.9


def test_a_missing_fleet_file_is_one_clear_error(tmp_path: object) -> None:
    with pytest.raises(ProtocolError, match=r"^fleet: cannot read .*nope\.yaml"):
        load_fleet("/nonexistent/nope.yaml")


def test_a_whole_shadow_document_over_8_kb_still_reads() -> None:
    # Given a GetThingShadow document whose metadata takes it past 8 KB (its state is small)
    document = {
        "state": {"reported": {"status": "waiting"}},
        "metadata": {"reported": {"note": {"timestamp": 1, "pad": "x" * 9000}}},
        "version": 4,
    }
    # When it is read, then the state comes through
    shadow = robot_shadow_from_payload(json.dumps(document).encode())
    assert (shadow.reported.status, shadow.version) == ("waiting", 4)
