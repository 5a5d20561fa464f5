"""Who may do what, end to end under moto: every role against every kind of action, the
confirmation of fleet-wide commands (in English and German), and each request's record in
the audit trail (a DynamoDB table, as on AWS).

What a person observes: the words spoken, the commands on the wire, and the trail.
"""

from __future__ import annotations

import copy
import json
from pathlib import Path
from typing import TYPE_CHECKING, Any

import boto3
import pytest
from skill_testkit import REGION, published, speech

from skill.audit_table import AuditTable
from skill.users_table import write_people
from tests.conftest import load_event
from tests.support.dynamodb_tables import create_audit_table
from vahr.domain.people import People, Person
from vahr.protocol.audit import verify

if TYPE_CHECKING:
    from collections.abc import Callable

    from skill_testkit import RobotDoubles


SUPERVISOR = "amzn1.ask.account.SUPERVISORSUSAN"
OPERATOR = "amzn1.ask.account.OPERATOROTTO"
VIEWER = "amzn1.ask.account.VIEWERVERA"
STRANGER = "amzn1.ask.account.NOBODYKNOWSME"
USERS_YAML = f"""
default_role: viewer
users:
  - {{id: {SUPERVISOR}, name: Susan, role: supervisor}}
  - {{id: {OPERATOR}, name: Otto, role: operator}}
  - {{id: {VIEWER}, name: Vera, role: viewer}}
"""
AUDIT_TABLE = "vahr-audit"
USERS_TABLE = "vahr-users"


def as_speaker(event: dict[str, Any], user: str, person: str | None = None) -> dict[str, Any]:
    """`event` as Alexa sends it for `user`'s account (and `person`'s recognised voice)."""
    event = copy.deepcopy(event)
    event["session"]["user"]["userId"] = user
    event["context"]["System"]["user"]["userId"] = user
    if person is not None:
        event["context"]["System"]["person"] = {"personId": person}
    return event


def answering(
    event: dict[str, Any], response: dict[str, Any], status: str, user: str
) -> dict[str, Any]:
    """The next request of the session: `user`'s yes or no (`status`) to the skill's
    Dialog.ConfirmIntent in `response`, as Alexa sends it."""
    follow = as_speaker(event, user)
    follow["session"]["new"] = False
    follow["session"]["attributes"] = response.get("sessionAttributes") or {}
    follow["request"]["dialogState"] = "IN_PROGRESS"
    follow["request"]["intent"]["confirmationStatus"] = status
    return follow


def directive(response: dict[str, Any]) -> str | None:
    directives = response["response"].get("directives") or []
    return directives[0]["type"] if directives else None


@pytest.fixture
def tables(aws: None) -> tuple[AuditTable, Any]:
    """The audit and users tables the stack makes (keys as infra/constructs/people_tables.py)."""
    client = boto3.client("dynamodb", region_name=REGION)
    create_audit_table(client, AUDIT_TABLE)
    client.create_table(
        TableName=USERS_TABLE,
        KeySchema=[{"AttributeName": "id", "KeyType": "HASH"}],
        AttributeDefinitions=[{"AttributeName": "id", "AttributeType": "S"}],
        BillingMode="PAY_PER_REQUEST",
    )
    return AuditTable(AUDIT_TABLE, client), client


@pytest.fixture
def users_file(tmp_path: Path) -> Path:
    path = tmp_path / "users.yaml"
    path.write_text(USERS_YAML, encoding="utf-8")
    return path


@pytest.fixture
def guarded(
    make_skill: Callable[..., Any], users_file: Path, tables: tuple[AuditTable, Any]
) -> Any:
    """The skill as `vahr up --users` runs it, its trail in the DynamoDB table."""
    return make_skill(users_file=str(users_file), audit_table=AUDIT_TABLE, ack_timeout_s=1.0)


# The table every role is held to: what each kind of action does for each speaker.
ACTIONS = {
    "question": "alexa_status",
    "command": "alexa_navigate",
    "fleet": "alexa_navigate_fleet",
    "stop": "alexa_emergency_stop",
}
EXPECTED = {
    (SUPERVISOR, "question"): "answered",
    (SUPERVISOR, "command"): "sent",
    (SUPERVISOR, "fleet"): "asked",
    (SUPERVISOR, "stop"): "sent",
    (OPERATOR, "question"): "answered",
    (OPERATOR, "command"): "sent",
    (OPERATOR, "fleet"): "refused",
    (OPERATOR, "stop"): "sent",
    (VIEWER, "question"): "answered",
    (VIEWER, "command"): "refused",
    (VIEWER, "fleet"): "refused",
    (VIEWER, "stop"): "sent",
    (STRANGER, "question"): "answered",
    (STRANGER, "command"): "refused",
    (STRANGER, "fleet"): "refused",
    (STRANGER, "stop"): "sent",
}


@pytest.mark.parametrize(("speaker", "action"), sorted(EXPECTED))
def test_each_role_may_do_what_it_allows_and_nothing_else(
    guarded: Any,
    robots: RobotDoubles,
    tables: tuple[AuditTable, Any],
    speaker: str,
    action: str,
) -> None:
    # Given the users file of a supervisor, an operator and a viewer, anyone else a viewer
    trail, _ = tables
    expected = EXPECTED[(speaker, action)]
    # When the speaker asks for the action
    response = guarded(as_speaker(load_event(ACTIONS[action]), speaker), None)
    said = speech(response)
    # Then the robots get a command only when the role allows it and nothing is asked first
    commands = [topic for topic, _ in published() if topic.endswith("/cmd")]
    assert bool(commands) == (expected == "sent"), (said, commands)
    if expected == "refused":
        assert "I sent nothing" in said
        assert directive(response) is None
    if expected == "asked":
        assert directive(response) == "Dialog.ConfirmIntent"
        assert said == "Send all robots to the loading zone, is that right?"
    # And the trail holds one record, naming who and what became of it
    [record] = trail.records()
    assert (record.who, record.outcome, record.channel) == (speaker, expected, "alexa")
    assert record.intent == load_event(ACTIONS[action])["request"]["intent"]["name"]


@pytest.mark.parametrize(
    ("speaker", "refusal"),
    [
        (
            VIEWER,
            "Sorry, Vera: as a viewer you may ask about the robots and stop them, but not send "
            "them. I sent nothing.",
        ),
        (
            OPERATOR,
            "Sorry, Otto: as an operator you may send robots and ask about them, but commands "
            "to the whole fleet or to many robots, and service changes, need a supervisor. "
            "I sent nothing.",
        ),
        (
            STRANGER,
            "Sorry, I don't know who is speaking, so you may ask about the robots and stop them, "
            "but not send them. I sent nothing.",
        ),
    ],
)
def test_a_refusal_says_what_the_person_may_do(
    guarded: Any, robots: RobotDoubles, speaker: str, refusal: str
) -> None:
    response = guarded(as_speaker(load_event("alexa_navigate_fleet"), speaker), None)
    assert speech(response) == refusal


def test_a_refusal_is_spoken_in_german(guarded: Any, robots: RobotDoubles) -> None:
    event = as_speaker(load_event("alexa_navigate_fleet"), VIEWER)
    event["request"]["locale"] = "de-DE"
    said = speech(guarded(event, None))
    assert said == (
        "Tut mir leid, Vera: Als Betrachter darfst du nach den Robotern fragen und sie "
        "anhalten, aber keine schicken. Ich habe nichts geschickt."
    )
    assert not published()


def test_a_supervisors_yes_carries_out_the_fleet_command(
    guarded: Any, robots: RobotDoubles, tables: tuple[AuditTable, Any]
) -> None:
    trail, _ = tables
    # Given a supervisor who sent all robots to the loading zone and was asked first
    event = as_speaker(load_event("alexa_navigate_fleet"), SUPERVISOR)
    asked = guarded(event, None)
    assert not published()
    # When she says yes
    done = guarded(answering(event, asked, "CONFIRMED", SUPERVISOR), None)
    # Then one command goes to the whole fleet, and both robots confirm it
    [(topic, payload)] = published()
    assert topic == "vahr/fleet/cmd"
    assert json.loads(payload)["params"] == {"zone": "LOADING"}
    assert speech(done) == "Both robots are on their way to the loading zone."
    # And the trail says she was asked, then confirmed, with the robots and the command
    first, second = trail.records()
    assert (first.outcome, second.outcome) == ("asked", "confirmed")
    assert second.robots == ["placebot1", "placebot2"]
    assert second.commands == [json.loads(payload)["id"]]
    assert (second.who, second.name, second.role) == (SUPERVISOR, "Susan", "supervisor")
    assert verify(trail.records(), trail.head()) == []


def test_a_no_sends_nothing(
    guarded: Any, robots: RobotDoubles, tables: tuple[AuditTable, Any]
) -> None:
    trail, _ = tables
    event = as_speaker(load_event("alexa_navigate_fleet"), SUPERVISOR)
    asked = guarded(event, None)
    answer = guarded(answering(event, asked, "DENIED", SUPERVISOR), None)
    assert speech(answer).startswith("Okay, I sent nothing.")
    assert not published()
    assert [record.outcome for record in trail.records()] == ["asked", "cancelled"]


def test_anything_else_said_after_the_question_sends_nothing(
    guarded: Any, robots: RobotDoubles, tables: tuple[AuditTable, Any]
) -> None:
    trail, _ = tables
    event = as_speaker(load_event("alexa_navigate_fleet"), SUPERVISOR)
    asked = guarded(event, None)
    # When she asks where the robots are instead of answering
    other = as_speaker(load_event("alexa_status"), SUPERVISOR)
    other["session"]["new"] = False
    other["session"]["attributes"] = asked["sessionAttributes"]
    response = guarded(other, None)
    # Then she hears the robots' state, nothing is sent, and the fleet command is dropped
    assert "placebot" in speech(response).lower()
    assert not [topic for topic, _ in published() if topic.endswith("/cmd")]
    assert "confirming" not in (response.get("sessionAttributes") or {})
    outcomes = [(r.intent, r.outcome) for r in trail.records()]
    assert outcomes == [
        ("NavigateIntent", "asked"),
        ("NavigateIntent", "cancelled"),
        ("StatusIntent", "answered"),
    ]


def test_another_persons_yes_does_not_confirm(
    guarded: Any, robots: RobotDoubles, tables: tuple[AuditTable, Any]
) -> None:
    trail, _ = tables
    # Given a supervisor asked to confirm a fleet command on a shared Echo
    event = as_speaker(load_event("alexa_navigate_fleet"), SUPERVISOR)
    asked = guarded(event, None)
    # When another person, recognised by voice, says yes in the same session
    yes = answering(event, asked, "CONFIRMED", SUPERVISOR)
    yes["context"]["System"]["person"] = {"personId": OPERATOR}
    response = guarded(yes, None)
    # Then nothing moves and the other person hears that it was not theirs to confirm
    assert speech(response) == (
        "Only the person who asked for that can confirm it, so I sent nothing."
    )
    assert not published()
    outcomes = [(r.who, r.outcome) for r in trail.records()]
    assert outcomes == [
        (SUPERVISOR, "asked"),
        (SUPERVISOR, "cancelled"),
        (OPERATOR, "refused"),
    ]


def test_confirmation_is_asked_and_answered_in_german(guarded: Any, robots: RobotDoubles) -> None:
    event = as_speaker(load_event("alexa_navigate_fleet"), SUPERVISOR)
    event["request"]["locale"] = "de-DE"
    asked = guarded(event, None)
    assert speech(asked) == "Alle Roboter nach Ladezone schicken: ist das richtig?"
    assert directive(asked) == "Dialog.ConfirmIntent"
    follow = answering(event, asked, "CONFIRMED", SUPERVISOR)
    done = guarded(follow, None)
    [(topic, _)] = published()
    assert topic == "vahr/fleet/cmd"
    assert "Ladezone" in speech(done)


def test_a_recognised_voice_is_preferred_to_the_account(guarded: Any, robots: RobotDoubles) -> None:
    # Given the viewer's Echo, on which Alexa recognised the operator's voice
    event = as_speaker(load_event("alexa_navigate"), VIEWER, person=OPERATOR)
    # When he sends placebot one to zone A, then the robot goes: the operator spoke
    speech(guarded(event, None))
    assert [topic for topic, _ in published()] == ["vahr/robots/placebot1/cmd"]


def test_an_unclear_robot_is_asked_about_never_widened(guarded: Any, robots: RobotDoubles) -> None:
    # "send robot to zone a": the words fit either robot
    event = as_speaker(load_event("alexa_navigate_robot_ambiguous"), OPERATOR)
    response = guarded(event, None)
    assert directive(response) == "Dialog.ElicitSlot"
    assert "I sent nothing" not in speech(response)
    assert not published()


def test_without_users_everyone_may_do_everything_at_once(
    make_skill: Callable[..., Any], robots: RobotDoubles
) -> None:
    skill = make_skill()
    response = skill(as_speaker(load_event("alexa_navigate_fleet"), STRANGER), None)
    assert directive(response) is None
    [(topic, _)] = published()
    assert topic == "vahr/fleet/cmd"


def test_the_fleet_file_can_turn_confirmation_off(
    make_skill: Callable[..., Any], users_file: Path, robots: RobotDoubles, tmp_path: Path
) -> None:
    fleet = Path(__file__).parents[3] / "fleet.yaml"
    mine = tmp_path / "fleet.yaml"
    mine.write_text(fleet.read_text() + "\nconfirmation: {enabled: false}\n", encoding="utf-8")
    skill = make_skill(users_file=str(users_file), fleet_file=str(mine))
    response = skill(as_speaker(load_event("alexa_navigate_fleet"), SUPERVISOR), None)
    assert directive(response) is None
    [(topic, _)] = published()
    assert topic == "vahr/fleet/cmd"


def test_the_users_table_gives_the_roles_on_aws(
    make_skill: Callable[..., Any], tables: tuple[AuditTable, Any], robots: RobotDoubles
) -> None:
    # Given the users file loaded into the table (vahr users import)
    _, client = tables
    write_people(People.from_yaml(USERS_YAML), USERS_TABLE, client)
    skill = make_skill(users_table=USERS_TABLE, audit_table=AUDIT_TABLE)
    # Then the viewer's command is refused and the operator's is sent
    assert "I sent nothing" in speech(skill(as_speaker(load_event("alexa_navigate"), VIEWER), None))
    assert not published()
    speech(skill(as_speaker(load_event("alexa_navigate"), OPERATOR), None))
    assert [topic for topic, _ in published()] == ["vahr/robots/placebot1/cmd"]


def test_an_unreadable_users_table_refuses_commands_but_never_a_stop(
    make_skill: Callable[..., Any], tables: tuple[AuditTable, Any], robots: RobotDoubles
) -> None:
    # Given a stack whose users table is gone
    skill = make_skill(users_table="no-such-table", audit_table=AUDIT_TABLE)
    # When the operator sends a robot, nothing moves and he hears why
    said = speech(skill(as_speaker(load_event("alexa_navigate"), OPERATOR), None))
    assert said.startswith("Sorry, I could not check who is speaking just now")
    assert not published()
    # But anyone's emergency stop still halts the robots
    speech(skill(as_speaker(load_event("alexa_emergency_stop"), OPERATOR), None))
    assert [topic for topic, _ in published()] == ["vahr/fleet/cmd"]


def test_an_audit_record_that_cannot_be_written_changes_no_reply(
    make_skill: Callable[..., Any], users_file: Path, robots: RobotDoubles, aws: None
) -> None:
    # Given a skill whose audit table does not exist
    skill = make_skill(users_file=str(users_file), audit_table="no-such-table")
    # When the operator sends a robot, it goes and he hears so
    said = speech(skill(as_speaker(load_event("alexa_navigate"), OPERATOR), None))
    assert said == "Placebot one is on its way to zone A."


def test_users_file_people_are_listed_with_default_role() -> None:
    people = People.from_yaml(USERS_YAML)
    assert people.person(VIEWER) == Person(id=VIEWER, name="Vera", role="viewer")
    assert people.person(STRANGER) == Person(id=STRANGER, role="viewer")
    assert not people.person(STRANGER).known


def test_vahr_users_import_loads_the_table_and_removes_who_left(
    tables: tuple[AuditTable, Any], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    from vahr.cli import main

    _, client = tables
    people = tmp_path / "people.yaml"
    people.write_text(USERS_YAML, encoding="utf-8")
    assert main(["users", "import", str(people), "--table", USERS_TABLE, "--region", REGION]) == 0
    assert capsys.readouterr().out == f"{USERS_TABLE}: 3 people, anyone else a viewer\n"
    # Vera leaves the file, and everyone else becomes an operator
    people.write_text(
        USERS_YAML.replace("default_role: viewer", "default_role: operator").replace(
            f"  - {{id: {VIEWER}, name: Vera, role: viewer}}\n", ""
        ),
        encoding="utf-8",
    )
    assert main(["users", "import", str(people), "--table", USERS_TABLE, "--region", REGION]) == 0
    items = client.scan(TableName=USERS_TABLE)["Items"]
    assert sorted((item["id"]["S"], item["role"]["S"]) for item in items) == [
        ("*", "operator"),
        (OPERATOR, "operator"),
        (SUPERVISOR, "supervisor"),
    ]
