"""The keyboard-and-mouse panel's orders and the participant's input, through the station's
API: what goes on the wire, what the running session's procedure refuses, one-line errors."""

from __future__ import annotations

import json
from datetime import UTC, datetime, timedelta
from typing import TYPE_CHECKING, Any

import pytest

from tests.support.station_stand_ins import RecordingAssistant, Wire
from vahr.protocol import decode_command, topics
from vahr.protocol.station_topics import Interaction, PuzzleInput, decode_station_input
from vahr.station.app import StationApp
from vahr.station.controls import Controls
from vahr.station.desk import Desk
from vahr.station.feed import Feed

if TYPE_CHECKING:
    from vahr.domain import Fleet


@pytest.fixture
def wire() -> Wire:
    return Wire()


@pytest.fixture
def feed(fleet: Fleet) -> Feed:
    return Feed(fleet)


@pytest.fixture
def app(fleet: Fleet, feed: Feed, wire: Wire) -> StationApp:
    desk = Desk(feed, wire.publish)
    return StationApp(
        feed=feed,
        controls=Controls(fleet, desk, wire.publish),
        desk=desk,
        assistant=RecordingAssistant(),
        push_to_talk=None,
        synthesize=None,
    )


def post(app: StationApp, path: str, body: object) -> tuple[int, dict[str, Any]]:
    reply = app.handle_json("POST", path, json.dumps(body).encode())
    return reply.status, json.loads(reply.body)


def session(method: str, task: str | None = "I", **extra: Any) -> dict[str, Any]:
    return {"session": f"P01-{method}-trial1", "participant": "P01", "method": method,
            "trial": 1, "task": task, **extra}  # fmt: skip


def test_a_navigate_goes_to_the_robots_topic_from_the_console(app: StationApp, wire: Wire) -> None:
    status, body = post(
        app, "/api/command", {"robot": "placebot2", "action": "navigate", "zone": "C"}
    )
    assert status == 200
    ((topic, payload),) = wire.sent
    command = decode_command(payload)
    assert topic == topics.robot_cmd("placebot2")
    assert (command.id, command.action, command.source) == (body["id"], "navigate", "console")
    assert command.params.zone == "C"  # type: ignore[union-attr]


def test_stop_all_is_one_message_on_the_fleet_topic(app: StationApp, wire: Wire) -> None:
    status, _ = post(app, "/api/stop", {})
    assert status == 200
    ((topic, payload),) = wire.sent
    assert topic == topics.FLEET_CMD and decode_command(payload).action == "stop"


@pytest.mark.parametrize(
    ("body", "error"),
    [
        (
            {"robot": "placebot9", "action": "navigate", "zone": "B"},
            "robot: 'placebot9' is not a robot; robots are placebot1, placebot2",
        ),
        (
            {"robot": "placebot1", "action": "navigate", "zone": "Q"},
            "zone: 'Q' is not a zone; zones are LOADING, A, B, C, D",
        ),
        (
            {"robot": "placebot1", "action": "deliver", "zone": "B"},
            "action: 'deliver' is not one the panel sends (navigate or stop)",
        ),
        ({"robot": "placebot1", "action": "navigate"}, "zone: a string is required"),
        ({"robot": 7, "action": "navigate", "zone": "B"}, "robot: a string is required"),
    ],
)
def test_a_bad_order_is_one_line_and_sends_nothing(
    app: StationApp, wire: Wire, body: dict[str, Any], error: str
) -> None:
    status, answer = post(app, "/api/command", body)
    assert (status, answer) == (400, {"error": error})
    assert wire.sent == []


@pytest.mark.parametrize("raw", [b"{", b"[1, 2]", b"\xff\xfe"])
def test_a_body_that_is_not_a_json_object_is_refused(app: StationApp, raw: bytes) -> None:
    reply = app.handle_json("POST", "/api/command", raw)
    assert reply.status == 400 and b"JSON" in reply.body


def test_in_a_keyboard_session_the_panel_follows_the_papers_procedure(
    app: StationApp, feed: Feed, wire: Wire
) -> None:
    feed.set_experiment(session("keyboard", "II"))
    status, _ = post(app, "/api/command", {"robot": "placebot1", "action": "navigate", "zone": "A"})
    assert status == 200
    # Between tasks no order is given
    feed.set_experiment(session("keyboard", None))
    status, answer = post(
        app, "/api/command", {"robot": "placebot1", "action": "navigate", "zone": "A"}
    )
    assert status == 409 and "no task is running" in answer["error"]
    assert len(wire.sent) == 1


def test_in_a_voice_session_orders_are_given_by_voice_but_stop_always_works(
    app: StationApp, feed: Feed, wire: Wire
) -> None:
    feed.set_experiment(session("vahr"))
    status, answer = post(
        app, "/api/command", {"robot": "placebot1", "action": "navigate", "zone": "A"}
    )
    assert status == 409
    assert answer["error"] == (
        "session P01-vahr-trial1 uses the vahr method: its orders are given by voice, "
        "not with the panel"
    )
    # Stopping is a safety control: never withheld
    assert post(app, "/api/stop", {})[0] == 200
    assert [decode_command(p).action for _, p in wire.sent] == ["stop"]


def test_the_weather_button_asks_the_assistant(app: StationApp) -> None:
    status, turn = post(
        app, "/api/say", {"utterance": "what is the weather", "origin": "station-weather"}
    )
    assert status == 200 and turn["speech"] == "It is sunny."
    assert app.assistant.asked == [("what is the weather", "station-weather")]  # type: ignore[union-attr]
    assert post(app, "/api/say", {"utterance": " "})[0] == 400
    assert post(app, "/api/say", {"utterance": "hi", "origin": "alexa"})[0] == 400
    assert post(app, "/api/say", {"utterance": "x" * 301})[0] == 400


def test_speech_needs_espeak(app: StationApp) -> None:
    status, answer = post(app, "/api/speech", {"text": "hello"})
    assert status == 503 and "espeak-ng" in answer["error"]


def test_input_without_a_session_is_not_logged_anywhere(app: StationApp, wire: Wire) -> None:
    now = datetime.now(UTC).isoformat()
    status, answer = post(app, "/api/puzzle", {"count": 1, "at": now, "sent": now})
    assert (status, answer) == (200, {"logged": False})
    assert wire.sent == []


def test_the_participants_input_goes_to_the_running_session(
    app: StationApp, feed: Feed, wire: Wire
) -> None:
    feed.set_experiment(session("keyboard"))
    start = datetime.now(UTC)
    body = {"id": "k3-1", "phase": "ended", "channel": "click", "text": "click zone B",
            "at": start.isoformat(), "sent": (start + timedelta(milliseconds=80)).isoformat(),
            "commands": ["c1"], "counts": True}  # fmt: skip
    assert post(app, "/api/interaction", body) == (202, {"logged": True})
    assert (
        post(app, "/api/puzzle", {"count": 2, "at": start.isoformat(), "sent": start.isoformat()})[
            0
        ]
        == 202
    )
    (topic, first), (_, second) = wire.sent
    assert topic == topics.EXPERIMENT_INPUT
    interaction = decode_station_input(first)
    assert isinstance(interaction, Interaction)
    assert (interaction.session, interaction.commands) == ("P01-keyboard-trial1", ["c1"])
    assert isinstance(decode_station_input(second), PuzzleInput)


@pytest.mark.parametrize(
    ("body", "field"),
    [
        ({"id": "x", "phase": "begun", "channel": "click"}, "phase"),
        ({"id": "x y", "phase": "started", "channel": "click"}, "id"),
        ({"id": "x", "phase": "started", "channel": "telepathy"}, "channel"),
        ({"id": "x", "phase": "started", "channel": "click", "at": "yesterday"}, "at"),
        ({"id": "x", "phase": "started", "channel": "click", "session": "P99-other"}, None),
    ],
)
def test_malformed_input_is_refused_naming_the_field(
    app: StationApp, feed: Feed, wire: Wire, body: dict[str, Any], field: str | None
) -> None:
    feed.set_experiment(session("keyboard"))
    now = datetime.now(UTC).isoformat()
    status, answer = post(app, "/api/interaction", {"at": now, **body})
    if field is None:
        # A session name from the page is ignored: input goes to the session that runs
        assert status == 202
        assert decode_station_input(wire.sent[0][1]).session == "P01-keyboard-trial1"
        return
    assert status == 400 and answer["error"].startswith(f"{field}:")
    assert wire.sent == []
