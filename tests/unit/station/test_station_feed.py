"""The station's feed: what a page is told, in which order, from the broker's messages."""

from __future__ import annotations

import json
from datetime import UTC, datetime
from typing import TYPE_CHECKING, Any

import msgspec
import pytest

from tests.conftest import load_event
from tests.support.station_stand_ins import RecordingAssistant, Wire
from vahr.dispatch import Task
from vahr.protocol import Event, Presence, ReportedPose, encode, new_command, topics, utc_now
from vahr.station.app import StationApp
from vahr.station.controls import Controls
from vahr.station.desk import Desk
from vahr.station.feed import ALERTS_LIMIT, Feed, Subscriber, fleet_view
from vahr.station.page_messages import (
    AlertAcknowledgedMessage,
    AnnouncementMessage,
    PageMessage,
    RobotsMessage,
    SnapshotMessage,
    TasksMessage,
    TurnMessage,
)

if TYPE_CHECKING:
    from vahr.domain import Fleet


PAGE = msgspec.json.Decoder(PageMessage)


class Clock:
    def __init__(self) -> None:
        self.ms = 1_000_000.0

    def __call__(self) -> float:
        return self.ms


@pytest.fixture
def clock() -> Clock:
    return Clock()


@pytest.fixture
def feed(fleet: Fleet, clock: Clock) -> Feed:
    return Feed(fleet, clock=clock)


def messages(subscriber: Subscriber) -> list[dict[str, Any]]:
    taken = subscriber.take(0) or []
    return [json.loads(m) for m in taken]


def event(kind: str, thing: str = "placebot1", **fields: Any) -> bytes:
    return encode(Event(event=kind, thing=thing, at=utc_now(), **fields))  # type: ignore[arg-type]


def documents(reported: dict[str, Any], version: int) -> bytes:
    return json.dumps(
        {"previous": None, "current": {"state": {"reported": reported}, "version": version}}
    ).encode()


def test_a_page_starts_from_a_snapshot_of_the_fleet_and_its_floor(feed: Feed) -> None:
    page = feed.subscribe()
    (snapshot,) = messages(page)
    assert snapshot["type"] == "snapshot"
    view = snapshot["fleet"]
    assert [r["key"] for r in view["robots"]] == ["1", "2"]
    assert {z["id"]: z["key"] for z in view["zones"]} == {
        "LOADING": "L", "A": "A", "B": "B", "C": "C", "D": "D"
    }  # fmt: skip
    assert view["floor"]["width"] == 10.5 and len(view["floor"]["arms"]) == 5
    assert set(snapshot["robots"]) == {"placebot1", "placebot2"}
    assert snapshot["experiment"] is None


def test_shadow_documents_reach_pages_in_order_and_old_versions_are_ignored(feed: Feed) -> None:
    page = feed.subscribe()
    messages(page)
    topic = topics.shadow("placebot1", "update/documents")
    # When the robot's shadow changes twice, then an older document arrives late
    feed.on_shadow_documents(topic, documents({"status": "navigating", "destination": "B"}, 4))
    feed.on_shadow_documents(topic, documents({"status": "idle", "zone": "B"}, 5))
    feed.load_shadow(
        "placebot1", json.dumps({"state": {"reported": {"status": "x"}}, "version": 3}).encode()
    )
    # Then the page, reading once, is told one change of the robot: the latest version,
    # with the fields as they are now and the one that went away
    (told,) = messages(page)
    assert told == {
        "type": "robots",
        "changes": [
            {
                "thing": "placebot1",
                "reported": {"status": "idle", "zone": "B"},
                "removed": ["destination"],
                "version": 5,
                "last_seen": 1_000_000.0,
            }
        ],
    }
    assert feed.snapshot()["robots"]["placebot1"]["reported"] == {"status": "idle", "zone": "B"}


def test_a_shadow_update_sends_only_the_fields_that_changed(feed: Feed, clock: Clock) -> None:
    topic = topics.shadow("placebot1", "update/documents")
    feed.on_shadow_documents(topic, documents({"status": "idle", "zone": "A", "cargo": False}, 1))
    page = feed.subscribe()
    messages(page)
    # When the robot starts to drive: its status changes, a destination appears
    feed.on_shadow_documents(
        topic,
        documents({"status": "navigating", "zone": "A", "cargo": False, "destination": "B"}, 2),
    )
    # Then the page is told those two fields and the version, nothing else
    (told,) = messages(page)
    assert told["changes"] == [
        {
            "thing": "placebot1",
            "reported": {"status": "navigating", "destination": "B"},
            "version": 2,
        }
    ]


def test_things_outside_the_fleet_and_named_shadows_are_not_drawn(feed: Feed) -> None:
    page = feed.subscribe()
    messages(page)
    feed.on_shadow_documents(topics.shadow("intruder", "update/documents"), documents({}, 1))
    feed.on_shadow_documents(
        topics.shadow("placebot1", "update/documents", "cfg"), documents({}, 1)
    )
    feed.on_shadow_documents(topics.shadow("placebot1", "update/documents"), b"not json")
    feed.on_event(topics.robot_events("placebot1"), event("arrived", thing="placebot2", zone="B"))
    assert messages(page) == []


def test_a_command_is_acknowledged_once_per_robot_with_its_latency(
    feed: Feed, clock: Clock
) -> None:
    page = feed.subscribe()
    messages(page)
    command = new_command("navigate", {"zone": "B"}, source="console")
    # Given a command seen on the robot's topic
    feed.on_command(topics.robot_cmd("placebot1"), encode(command))
    # When the robot accepts it 12 ms later, then its shadow says so too
    clock.ms += 12
    feed.on_event(topics.robot_events("placebot1"), event("accepted", command_id=command.id))
    clock.ms += 5
    feed.on_shadow_documents(
        topics.shadow("placebot1", "update/documents"),
        documents(
            {"last_command": {"id": command.id, "action": "navigate", "result": "accepted"}}, 9
        ),
    )
    told = messages(page)
    # Then the page is told the command, one acknowledgment with its latency, the shadow
    assert [m["type"] for m in told] == ["command", "ack", "robots"]
    (change,) = told[2]["changes"]
    assert change["last_event"]["event"] == "accepted" and change["version"] == 9
    assert told[0]["target"] == "placebot1" and told[0]["source"] == "console"
    assert told[1] == {
        "type": "ack", "id": command.id, "thing": "placebot1", "event": "accepted", "latency_ms": 12.0
    }  # fmt: skip
    # And a console order is part of the conversation a new page starts from
    conversation = feed.snapshot()["conversation"]
    assert conversation[-1]["id"] == command.id and conversation[-1]["acks"]["placebot1"]


def test_a_fleet_command_waits_for_every_robot(feed: Feed) -> None:
    command = new_command("stop", source="console")
    feed.on_command(topics.FLEET_CMD, encode(command))
    feed.on_event(
        topics.robot_events("placebot2"), event("stopped", thing="placebot2", command_id=command.id)
    )
    seen = feed.snapshot()["commands"][command.id]
    assert seen["robots"] == ["placebot1", "placebot2"]
    assert set(seen["acks"]) == {"placebot2"}


def test_turns_name_the_robots_they_concern(feed: Feed) -> None:
    command = new_command("navigate", {"zone": "C"}, source="alexa")
    feed.on_command(topics.robot_cmd("placebot2"), encode(command))
    turn = {
        "utterance": "send placebot two to zone c",
        "speech": "Placebot two is on its way to zone C.",
        "intent": "NavigateIntent",
        "slots": {"robot": {"value": "placebot two", "id": "placebot2"}},
        "commands": [command.id],
        "origin": "station-voice",
        "heard": {"transcript": "send placebot two to zone c", "confidence": 0.8, "accepted": True},
    }
    feed.on_turn(topics.ASSISTANT_TURNS, json.dumps(turn).encode())
    feed.on_turn(topics.ASSISTANT_TURNS, b'{"utterance": 5}')  # not a turn: ignored
    conversation = feed.snapshot()["conversation"]
    # The assistant's own command is shown inside its turn, not on its own
    assert [entry["type"] for entry in conversation] == ["turn"]
    assert conversation[0]["robots"] == ["placebot2"]
    assert conversation[0]["heard"]["confidence"] == 0.8


def test_the_robots_own_exchanges_with_the_assistant_are_conversation(feed: Feed) -> None:
    feed.on_event(
        topics.robot_events("placebot1"), event("said", text="Alexa, what is the weather?")
    )
    feed.on_event(topics.robot_events("placebot1"), event("progress", progress=0.5))
    feed.on_event(
        topics.robot_events("placebot1"), event("interpreted", intent="sunny", confidence=0.9)
    )
    assert [e["event"] for e in feed.snapshot()["conversation"]] == ["said", "interpreted"]


def test_presence_marks_a_robot_offline_and_keeps_when_it_was_last_seen(
    feed: Feed, clock: Clock
) -> None:
    topic = topics.robot_presence("placebot1")
    feed.on_presence(topic, encode(Presence(online=True, at=utc_now())))
    seen = clock.ms
    clock.ms += 60_000
    feed.on_presence(topic, encode(Presence(online=False, at=utc_now())))
    robot = feed.snapshot()["robots"]["placebot1"]
    assert robot["online"] is False and robot["last_seen"] == seen


def test_a_page_that_falls_behind_gets_each_robots_latest_progress(feed: Feed) -> None:
    page = feed.subscribe()
    messages(page)
    for step in range(5):
        pose = ReportedPose(1.0 + step, 3.0)
        feed.on_event(
            topics.robot_events("placebot1"), event("progress", progress=step / 5, pose=pose)
        )
    feed.on_event(
        topics.robot_events("placebot2"), event("progress", thing="placebot2", progress=0.1)
    )
    (told,) = messages(page)
    assert [(c["thing"], c["progress"]["progress"]) for c in told["changes"]] == [
        ("placebot1", 0.8),
        ("placebot2", 0.1),
    ]
    assert told["changes"][0]["progress"]["pose"]["x"] == 5.0


def test_a_page_too_far_behind_is_dropped_and_reconnects_from_a_snapshot(feed: Feed) -> None:
    # (what robots say to the assistant is never merged: each line is the conversation's)
    page = feed.subscribe(limit=3)
    for _ in range(5):
        feed.on_event(topics.robot_events("placebot1"), event("said", text="Alexa, hello"))
    assert page.overflowed and page.take(0) is None
    assert feed.subscribers == 0


def test_an_experiment_status_and_its_clearing_reach_pages(feed: Feed) -> None:
    page = feed.subscribe()
    messages(page)
    status = {
        "session": "P01-keyboard-trial1",
        "participant": "P01",
        "method": "keyboard",
        "trial": 1,
    }
    feed.on_experiment_status(topics.EXPERIMENT_STATUS, json.dumps(status).encode())
    feed.on_experiment_status(topics.EXPERIMENT_STATUS, b'{"session": "bad name!"}')
    feed.on_experiment_status(topics.EXPERIMENT_STATUS, b"")
    told = messages(page)
    assert [m["status"] and m["status"]["session"] for m in told] == ["P01-keyboard-trial1", None]


def test_a_fleet_without_a_floor_gets_keys_and_one(fleet: Fleet) -> None:
    bare = msgspec.structs.replace(fleet, floor=None)
    view = fleet_view(bare)
    assert view.floor.width > 0 and len(view.floor.walls) == 4


def test_every_message_a_page_is_sent_is_a_page_message_of_the_contract(
    feed: Feed, clock: Clock
) -> None:
    page = feed.subscribe()
    command = new_command("navigate", {"zone": "B"}, source="console")
    # When every kind of broker message reaches the feed
    feed.on_command(topics.robot_cmd("placebot1"), encode(command))
    feed.on_event(topics.robot_events("placebot1"), event("accepted", command_id=command.id))
    feed.on_shadow_documents(
        topics.shadow("placebot1", "update/documents"),
        documents({"status": "navigating", "destination": "B", "extra": [1]}, 3),
    )
    feed.on_presence(
        topics.robot_presence("placebot2"), encode(Presence(online=True, at=utc_now()))
    )
    feed.on_turn(topics.ASSISTANT_TURNS, b'{"utterance": "hi", "speech": "Hello."}')
    feed.on_experiment_status(
        topics.EXPERIMENT_STATUS,
        b'{"session": "P01-vahr-trial1", "participant": "P01", "method": "vahr", "trial": 1}',
    )
    feed.on_announcement(topics.ASSISTANT_ANNOUNCEMENTS, stuck_announcement())
    feed.acknowledge(load_event("announcement_stuck")["id"])
    # Then each message the page gets decodes as the contract's struct of its type
    told = [PAGE.decode(message) for message in page.take(0) or []]
    assert [m.__struct_config__.tag for m in told] == [
        "snapshot", "command", "ack", "robots", "turn", "experiment",
        "announcement", "alert_acknowledged",
    ]  # fmt: skip
    # And what the robot reported is passed on, fields beyond the contract too, beside
    # the other robot's presence
    robots = told[3]
    assert isinstance(robots, RobotsMessage)
    shadow, presence = robots.changes
    assert shadow.reported == {"status": "navigating", "destination": "B", "extra": [1]}
    assert presence.thing == "placebot2" and presence.online is True
    # And a new page's snapshot holds the same, as a page message too
    (snapshot,) = [PAGE.decode(m) for m in feed.subscribe().take(0) or []]
    assert isinstance(snapshot, SnapshotMessage)
    assert snapshot.commands[command.id].acks["placebot1"].event == "accepted"


def test_a_rejected_command_or_a_ping_answered_mid_drive_does_not_end_the_drive(
    feed: Feed,
) -> None:
    events = topics.robot_events("placebot1")
    feed.on_event(events, event("progress", progress=0.4, pose=ReportedPose(2.0, 3.0)))
    # When the robot rejects a bad command and answers a ping while it drives
    feed.on_event(events, event("rejected", reason="params.zone: 'Q' is not a zone"))
    feed.on_event(events, event("done", action="ping"))
    # Then the drive's progress is still shown
    assert feed.snapshot()["robots"]["placebot1"]["progress"]["progress"] == 0.4
    # And arriving ends it
    feed.on_event(events, event("arrived", zone="B"))
    assert feed.snapshot()["robots"]["placebot1"]["progress"] is None


def test_the_stations_own_turns_reach_pages_as_the_brokers_do(feed: Feed) -> None:
    page = feed.subscribe()
    messages(page)
    # The in-process simulator's turn message keeps its defaults and its time as text
    simulated = {
        "speech": "Hello.", "intent": None, "slots": {}, "commands": [], "latency_ms": 3.0,
        "session_open": False, "request_type": "IntentRequest", "reprompt": None,
        "origin": "station", "utterance": "hi", "at": "2026-11-23T10:00:00+00:00",
    }  # fmt: skip
    feed.add_turn(simulated)
    feed.on_turn(topics.ASSISTANT_TURNS, json.dumps(simulated).encode())
    feed.add_turn({**simulated, "origin": "Not An Origin"})  # not a turn: ignored
    first, second = (PAGE.decode(message) for message in page.take(0) or [])
    # Then the page sees one turn, whichever way it came (defaults may be left out)
    assert first == second
    assert isinstance(first, TurnMessage) and first.robots == [] and first.origin == "station"
    assert first.at == datetime(2026, 11, 23, 10, 0, tzinfo=UTC)


# -- announcements: the assistant telling without being asked ------------------------------


def stuck_announcement(**changes: Any) -> bytes:
    """The local announcer's message for a stuck placebot1 (tests/events), with `changes`."""
    return json.dumps({**load_event("announcement_stuck"), **changes}).encode()


def test_the_feed_listens_for_announcements_on_every_deployment(feed: Feed) -> None:
    # Both the local announcer and the cloud's announcer function publish them
    for turns in (True, False):
        routes = dict(feed.routes(turns=turns))
        assert routes[topics.ASSISTANT_ANNOUNCEMENTS] == feed.on_announcement


def test_an_announcement_reaches_pages_as_an_alert_and_in_the_conversation(feed: Feed) -> None:
    page = feed.subscribe()
    messages(page)
    # When the announcer says placebot1 is stuck
    feed.on_announcement(topics.ASSISTANT_ANNOUNCEMENTS, stuck_announcement())
    # Then every page is told, naming the robot and in the assistant's words
    (told,) = [PAGE.decode(m) for m in page.take(0) or []]
    assert isinstance(told, AnnouncementMessage)
    assert (told.thing, told.kind, told.robots) == ("placebot1", "stuck", ["placebot1"])
    assert told.speech == "Placebot one is stuck on its way to zone B and needs your help."
    # And a page opened now starts with it as an open alert, and in the conversation
    snapshot = feed.snapshot()
    assert [a["id"] for a in snapshot["alerts"]] == [told.id]
    assert snapshot["conversation"][-1]["type"] == "announcement"


def test_an_announcement_delivered_twice_is_shown_once(feed: Feed) -> None:
    page = feed.subscribe()
    messages(page)
    feed.on_announcement(topics.ASSISTANT_ANNOUNCEMENTS, stuck_announcement())
    feed.on_announcement(topics.ASSISTANT_ANNOUNCEMENTS, stuck_announcement())
    assert [m["type"] for m in messages(page)] == ["announcement"]
    assert len(feed.snapshot()["alerts"]) == 1


def test_a_malformed_announcement_is_ignored(feed: Feed) -> None:
    page = feed.subscribe()
    messages(page)
    feed.on_announcement(topics.ASSISTANT_ANNOUNCEMENTS, b"not json")
    feed.on_announcement(topics.ASSISTANT_ANNOUNCEMENTS, stuck_announcement(kind="bored"))
    assert messages(page) == []
    assert feed.snapshot()["alerts"] == []


def test_acknowledging_an_alert_lets_go_of_it_and_its_repeats_on_every_page(
    feed: Feed,
) -> None:
    first = json.loads(stuck_announcement())["id"]
    # Given placebot1 announced stuck twice (the fault cleared and came back) and placebot2
    # announced offline, none acknowledged
    feed.on_announcement(topics.ASSISTANT_ANNOUNCEMENTS, stuck_announcement())
    feed.on_announcement(topics.ASSISTANT_ANNOUNCEMENTS, stuck_announcement(id="vahr~stuck~2"))
    feed.on_announcement(
        topics.ASSISTANT_ANNOUNCEMENTS,
        stuck_announcement(
            id="vahr~offline~1",
            thing="placebot2",
            kind="offline",
            speech="Placebot two has gone offline.",
        ),
    )
    pages = [feed.subscribe(), feed.subscribe()]
    for page in pages:
        messages(page)
    # When someone acknowledges placebot1's first alert
    acknowledged = feed.acknowledge(first)
    # Then both of placebot1's stuck alerts go, on every page, and placebot2's stays
    assert acknowledged == [first, "vahr~stuck~2"]
    for page in pages:
        (told,) = [PAGE.decode(m) for m in page.take(0) or []]
        assert told == AlertAcknowledgedMessage(ids=[first, "vahr~stuck~2"])
    assert [a["id"] for a in feed.snapshot()["alerts"]] == ["vahr~offline~1"]
    # And acknowledging again, or an id never announced, changes nothing
    assert feed.acknowledge(first) == []
    assert feed.acknowledge("vahr~nothing~0") == []
    assert all(messages(page) == [] for page in pages)


def test_open_alerts_are_bounded_oldest_first_out(feed: Feed) -> None:
    for index in range(ALERTS_LIMIT + 3):
        feed.on_announcement(
            topics.ASSISTANT_ANNOUNCEMENTS, stuck_announcement(id=f"vahr~stuck~{index}")
        )
    alerts = feed.snapshot()["alerts"]
    assert len(alerts) == ALERTS_LIMIT
    assert alerts[0]["id"] == "vahr~stuck~3"


def test_an_alert_is_acknowledged_through_the_stations_api(fleet: Fleet, feed: Feed) -> None:
    wire = Wire()
    desk = Desk(feed, wire.publish)
    app = StationApp(
        feed=feed,
        controls=Controls(fleet, desk, wire.publish),
        desk=desk,
        assistant=RecordingAssistant(),
        push_to_talk=None,
        synthesize=None,
    )
    feed.on_announcement(topics.ASSISTANT_ANNOUNCEMENTS, stuck_announcement())
    announced = json.loads(stuck_announcement())["id"]
    # When a page posts the acknowledgment, then the station answers what it acknowledged
    reply = app.handle_json("POST", "/api/acknowledge", json.dumps({"id": announced}).encode())
    assert (reply.status, json.loads(reply.body)) == (200, {"acknowledged": [announced]})
    assert feed.snapshot()["alerts"] == []
    # And a body without an id is one line naming the field
    reply = app.handle_json("POST", "/api/acknowledge", b"{}")
    assert (reply.status, json.loads(reply.body)) == (400, {"error": "id: a string is required"})
    # And nothing went to the robots
    assert wire.sent == []


def test_changes_not_taken_yet_merge_into_the_state_the_page_would_reach(feed: Feed) -> None:
    shadow = topics.shadow("placebot1", "update/documents")
    feed.on_shadow_documents(shadow, documents({"status": "idle", "zone": "A", "task": "x"}, 1))
    page = feed.subscribe()
    (snapshot,) = messages(page)
    # When the robot drives off (task gone, destination new), goes offline and comes back
    feed.on_shadow_documents(shadow, documents({"status": "navigating", "zone": "A"}, 2))
    feed.on_shadow_documents(
        shadow, documents({"status": "navigating", "zone": None, "destination": "B"}, 3)
    )
    presence = topics.robot_presence("placebot1")
    feed.on_presence(presence, encode(Presence(online=False, at=utc_now())))
    feed.on_presence(presence, encode(Presence(online=True, at=utc_now())))
    # Then the one change the page reads takes it from its snapshot to the feed's state
    (told,) = messages(page)
    (change,) = told["changes"]
    robot = snapshot["robots"]["placebot1"]
    robot["reported"] = {**robot["reported"], **change["reported"]}
    for key in change["removed"]:
        del robot["reported"][key]
    robot.update({k: v for k, v in change.items() if k not in ("thing", "reported", "removed")})
    assert robot == feed.snapshot()["robots"]["placebot1"]
    assert change["online"] is True and change["version"] == 3


def test_the_task_queue_reaches_pages_when_it_changed_and_new_pages_start_with_it(
    feed: Feed,
) -> None:
    page = feed.subscribe()
    messages(page)
    queued = Task(
        id="t1", request="r1", kind="deliver", zone="C", created_at="2026-11-26T23:00:00Z"
    )
    # When the dispatcher's queue is read three times, changing once in between
    feed.set_tasks(TasksMessage(tasks=[queued], available=True))
    feed.set_tasks(TasksMessage(tasks=[queued], available=True))
    taken = msgspec.structs.replace(queued, status="assigned", thing="placebot2")
    feed.set_tasks(TasksMessage(tasks=[taken], available=True))
    # Then the page, reading once, is told the latest queue once
    (told,) = messages(page)
    assert told["type"] == "tasks"
    assert [(t["status"], t["thing"]) for t in told["tasks"]] == [("assigned", "placebot2")]
    # And a page opened now starts from it
    assert feed.snapshot()["tasks"]["tasks"][0]["thing"] == "placebot2"


def test_a_fleet_commands_answers_reach_a_page_as_one_message(feed: Feed) -> None:
    page = feed.subscribe()
    messages(page)
    # When both robots accept a command, drive, and one arrives, all before the page reads
    for thing in ("placebot1", "placebot2"):
        feed.on_event(topics.robot_events(thing), event("accepted", thing=thing))
        pose = ReportedPose(2.0, 3.0)
        feed.on_event(
            topics.robot_events(thing), event("progress", thing=thing, progress=0.5, pose=pose)
        )
    feed.on_event(topics.robot_events("placebot1"), event("arrived", zone="B"))
    # Then the page gets one message: per robot its latest event, and the drive's state
    # after it (over for placebot one, half way for placebot two)
    (told,) = messages(page)
    one, two = told["changes"]
    assert (one["last_event"]["event"], one["progress"]) == ("arrived", None)
    assert (two["last_event"]["event"], two["progress"]["progress"]) == ("accepted", 0.5)
