"""The users file and what each role may do (pure)."""

from __future__ import annotations

import pytest

from vahr.domain.people import OPEN, People, Person, confirmation_on, token_hash
from vahr.protocol import ProtocolError

TOKEN = "a-station-token-for-susan-0123"
FILE = f"""
default_role: operator
users:
  - {{id: amzn1.ask.account.SUSAN, name: Susan, role: supervisor, token_sha256: {token_hash(TOKEN)}}}
  - {{id: amzn1.ask.person.VERA, name: Vera, role: viewer}}
"""


def test_a_users_file_names_people_and_everyone_elses_role() -> None:
    people = People.from_yaml(FILE)
    assert people.person("amzn1.ask.person.VERA") == Person(
        id="amzn1.ask.person.VERA", name="Vera", role="viewer"
    )
    stranger = people.person("amzn1.ask.account.NOBODY")
    assert (stranger.role, stranger.known, stranger.shown) == (
        "operator", False, "amzn1.ask.account.NOBODY",
    )  # fmt: skip
    assert people.signed_in(TOKEN) == people.person("amzn1.ask.account.SUSAN")
    assert people.signed_in("another-token") is None


def test_without_a_file_everyone_is_a_supervisor() -> None:
    assert OPEN.person("anyone").role == "supervisor"


@pytest.mark.parametrize(
    ("text", "error"),
    [
        ("", "users: the file is empty; it needs users: (and default_role:)"),
        ("users: [", "users: is not valid YAML"),
        (
            "default_role: boss",
            "default_role: 'boss' is not a role; roles are viewer, operator, supervisor",
        ),  # fmt: skip
        ("users: [{id: a, name: A, role: admin}]", "users.0.role: 'admin' is not a role"),
        ("users: [{id: a, role: viewer}]", "users.0.name: is required but missing"),
        ("users: [{id: a, name: A, role: viewer, age: 3}]", "users.0.age: is not a known field"),
        (
            "users: [{id: a, name: A, role: viewer}, {id: a, name: B, role: viewer}]",
            "users.1.id: 'a' is used twice (also users.0.id)",
        ),
        ("users: [{id: '*', name: A, role: viewer}]", "users.0.id: '*' means everyone else"),
        ("users: [{id: a, name: A, role: viewer, token_sha256: abc}]", "users.0.token_sha256"),
    ],
)
def test_a_broken_users_file_is_one_line_naming_the_entry(text: str, error: str) -> None:
    with pytest.raises(ProtocolError) as raised:
        People.from_yaml(text)
    assert str(raised.value).startswith(error), str(raised.value)


@pytest.mark.parametrize(
    ("explicit", "fleet_file", "people_known", "on"),
    [
        (None, None, False, False),
        (None, None, True, True),
        (None, False, True, False),
        (None, True, False, True),
        (False, True, True, False),
    ],
)
def test_confirmation_is_on_when_people_are_known_unless_said_otherwise(
    explicit: bool | None, fleet_file: bool | None, people_known: bool, on: bool
) -> None:
    assert confirmation_on(explicit, fleet_file, people_known) is on
