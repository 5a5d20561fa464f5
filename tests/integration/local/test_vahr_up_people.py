"""End to end: `vahr up --users FILE`, people speaking with `vahr say --user`, and the audit
trail read back with `vahr audit` (JSON, CSV, and its verification).

The users file names a supervisor, an operator and a viewer, and anyone else is a viewer.
What a person observes: the words spoken, the robots moving (their events), and the trail.
"""

from __future__ import annotations

import csv
import io
import json
import sqlite3
import subprocess
from typing import TYPE_CHECKING, Any

import pytest

from tests.support.vahr_up import ROOT, VAHR, Up, clean_env, start_up, stop_up
from tests.support.vahr_up import say as say_to

if TYPE_CHECKING:
    from collections.abc import Iterator
    from pathlib import Path

SUSAN = "amzn1.ask.account.SUPERVISORSUSAN"
OTTO = "amzn1.ask.account.OPERATOROTTO"
VERA = "amzn1.ask.account.VIEWERVERA"
NOBODY = "amzn1.ask.account.SOMEBODYUNKNOWN"
USERS = f"""
default_role: viewer
users:
  - {{id: {SUSAN}, name: Susan, role: supervisor}}
  - {{id: {OTTO}, name: Otto, role: operator}}
  - {{id: {VERA}, name: Vera, role: viewer}}
"""


@pytest.fixture(scope="module")
def up(tmp_path_factory: pytest.TempPathFactory) -> Iterator[tuple[Up, Path]]:
    state = tmp_path_factory.mktemp("people")
    users = tmp_path_factory.mktemp("people-file") / "users.yaml"
    users.write_text(USERS, encoding="utf-8")
    running = start_up(state, "--users", str(users), "--sim-speed-factor", "20")
    try:
        yield running, state
    finally:
        stop_up(running.process)


def say(up: tuple[Up, Path], who: str, utterance: str) -> dict[str, Any]:
    return say_to(up[0].endpoints["api"], utterance, "--user", who)


def audit(up: tuple[Up, Path], *flags: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [*VAHR, "audit", "--api", up[0].endpoints["api"], *flags],
        cwd=ROOT, env=clean_env(), capture_output=True, text=True, timeout=30, check=False,
    )  # fmt: skip


def test_people_may_do_what_their_roles_allow_and_the_trail_says_who_did_what(
    up: tuple[Up, Path],
) -> None:
    running = up[0]
    # The viewer's status question is answered
    asked = say(up, VERA, "where are the robots")
    assert asked["intent"] == "StatusIntent" and "placebot" in asked["speech"].lower()
    # The viewer's and an unknown person's commands move nothing
    for who in (VERA, NOBODY):
        refused = say(up, who, "send placebot one to zone b")
        assert refused["commands"] == [] and "I sent nothing" in refused["speech"]
    # The operator's command moves the robot
    sent = say(up, OTTO, "send placebot one to zone b")
    [command] = sent["commands"]
    assert running.wait_event(command, "arrived")["zone"] == "B"
    # The operator's fleet-wide command moves nothing
    fleet = say(up, OTTO, "send all robots to zone a")
    assert fleet["commands"] == [] and "need a supervisor" in fleet["speech"]
    # The supervisor's asks first; another person's yes is not hers, and moves nothing
    question = say(up, SUSAN, "send all robots to zone a")
    assert question["speech"] == "Send all robots to zone A, is that right?"
    assert question["commands"] == [] and question["session_open"]
    assert say(up, OTTO, "yes")["commands"] == []
    # Her yes moves both robots
    done = say(up, SUSAN, "yes")
    [command] = done["commands"]
    assert done["speech"] == "Both robots are on their way to zone A."
    arrivals = set()
    while len(arrivals) < 2:
        event = running.wait_event(command, "arrived")
        assert event["zone"] == "A"
        arrivals.add(event["thing"])

    # The trail lists each, with who and the channel (JSON)
    listed = audit(up, "--json")
    assert listed.returncode == 0, listed.stderr
    records = json.loads(listed.stdout)
    seen = [(r["who"], r["name"], r["channel"], r["intent"], r["outcome"]) for r in records]
    # (Otto's stray "yes", in a session of his own with no question open, asked for nothing
    # the trail records.)
    assert seen == [
        (VERA, "Vera", "alexa", "StatusIntent", "answered"),
        (VERA, "Vera", "alexa", "NavigateIntent", "refused"),
        (NOBODY, None, "alexa", "NavigateIntent", "refused"),
        (OTTO, "Otto", "alexa", "NavigateIntent", "sent"),
        (OTTO, "Otto", "alexa", "NavigateIntent", "refused"),
        (SUSAN, "Susan", "alexa", "NavigateIntent", "asked"),
        (SUSAN, "Susan", "alexa", "NavigateIntent", "confirmed"),
    ]
    assert records[3]["robots"] == ["placebot1"] and records[3]["words"] == (
        "send placebot one to zone b"
    )
    assert records[6]["robots"] == ["placebot1", "placebot2"]
    assert records[6]["commands"] == [command]
    # The same records as CSV
    table = list(csv.DictReader(io.StringIO(audit(up, "--csv").stdout)))
    assert [(row["who"], row["channel"], row["outcome"]) for row in table] == [
        (r["who"], r["channel"], r["outcome"]) for r in records
    ]
    assert table[6]["robots"] == "placebot1 placebot2"
    # And it verifies
    verified = audit(up, "--verify")
    assert verified.returncode == 0
    assert verified.stdout.startswith(f"The audit trail is intact: {len(records)} records")


def test_a_trail_edited_behind_the_stacks_back_fails_verification(up: tuple[Up, Path]) -> None:
    # Given someone who edits the trail's file, dropping its guard
    say(up, VERA, "where are the robots")
    db = sqlite3.connect(up[1] / "audit.sqlite3")
    db.execute("DROP TRIGGER records_never_change")
    [(text,)] = db.execute("SELECT record FROM records WHERE seq = 2")
    edited = json.loads(text) | {"outcome": "sent"}
    db.execute("UPDATE records SET record = ? WHERE seq = 2", (json.dumps(edited),))
    db.commit()
    db.close()
    # When the trail is verified, Then it says which record and exits non-zero
    verified = audit(up, "--verify")
    assert verified.returncode == 1
    assert "altered: record 2: its content does not match its hash (altered)" in verified.stdout
    as_json = json.loads(audit(up, "--verify", "--json").stdout)
    assert as_json["intact"] is False and as_json["faults"][0]["seq"] == 2
