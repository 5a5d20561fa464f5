"""Who may do what: people, their roles, and the kinds of action a role allows.

A person is who Alexa says is speaking: the `personId` when Alexa recognised the voice
(Alexa personalization), else the account's `userId`. The users file (`vahr up --users
FILE`; on AWS the same file loaded into a DynamoDB table) names people and their roles:

```yaml
default_role: viewer          # anyone not listed (viewer unless the file says otherwise)
users:
  - id: amzn1.ask.account.AF3...   # an Alexa userId, or a personId
    name: Dr. Weber
    role: supervisor
    token_sha256: 9f86d0...        # optional: signs in at the operator station
```

Every request is one kind of action (`ActionKind`), decided from what was asked, never
from who asked: a question, a command to robots, a fleet-wide or disruptive command, or a
stop. A role allows a set of kinds (`ALLOWED`): a viewer asks, an operator also commands
robots, a supervisor also gives fleet-wide commands, service changes and closures. Anyone
may stop the robots, always. Without a users file nobody is known and everyone is a
supervisor (`OPEN`), as VAHR always was.
"""

from __future__ import annotations

import hashlib
import hmac
import os
from functools import cached_property
from typing import Annotated, Literal

import msgspec

from vahr.protocol.errors import ProtocolError, from_validation_error

Role = Literal["viewer", "operator", "supervisor"]
ROLES: tuple[Role, ...] = ("viewer", "operator", "supervisor")

# What a request does, as far as permission goes:
# - question: asks and changes nothing (status, the queue, the weather, help);
# - command: moves or tasks robots, one or a few (a robot to a zone, a delivery, a task
#   cancelled);
# - fleet: affects the whole fleet or much of it, or changes the service (all robots, a
#   group larger than the threshold, every idle robot, cancel all, out of service, a zone
#   closed or opened): a supervisor's, and confirmed with a spoken yes first;
# - stop: halts robots at once: anyone's, never asked about first.
ActionKind = Literal["question", "command", "fleet", "stop"]
ACTION_KINDS: tuple[ActionKind, ...] = ("question", "command", "fleet", "stop")

ALLOWED: dict[Role, frozenset[ActionKind]] = {
    "viewer": frozenset({"question", "stop"}),
    "operator": frozenset({"question", "stop", "command"}),
    "supervisor": frozenset({"question", "stop", "command", "fleet"}),
}
# The kinds confirmed with a spoken yes before anything is sent (when confirmation is on).
CONFIRMED_KINDS: frozenset[ActionKind] = frozenset({"fleet"})
# The users table's item (and the users file's meaning) for everyone not listed.
EVERYONE_ELSE = "*"
MAX_ID_CHARS = 255  # Alexa's userId and personId are never longer

PersonId = Annotated[str, msgspec.Meta(min_length=1, max_length=MAX_ID_CHARS)]
PersonName = Annotated[str, msgspec.Meta(min_length=1, max_length=100)]
TokenHash = Annotated[str, msgspec.Meta(pattern=r"^[0-9a-f]{64}$")]


def may(role: Role, kind: ActionKind) -> bool:
    """Whether `role` may do an action of `kind`."""
    return kind in ALLOWED[role]


def confirmation_on(explicit: bool | None, fleet_file: bool | None, people_known: bool) -> bool:
    """Whether fleet-wide commands are confirmed first: as the deployment says explicitly
    (the paper's experiment says no), else as the fleet file says, else whenever people
    are known."""
    if explicit is not None:
        return explicit
    if fleet_file is not None:
        return fleet_file
    return people_known


def valid_person_id(value: str) -> bool:
    """Whether `value` can be an Alexa userId or personId: 1 to 255 printable characters,
    none of them a space."""
    return 0 < len(value) <= MAX_ID_CHARS and value.isprintable() and " " not in value


def token_hash(token: str) -> str:
    """The SHA-256 of a station token, as the users file keeps it (hex)."""
    return hashlib.sha256(token.encode()).hexdigest()


class Person(
    msgspec.Struct, frozen=True, kw_only=True, forbid_unknown_fields=True, omit_defaults=True
):
    """One person: their Alexa id, their name and their role. Someone the users file does
    not list has no name (`known` is False) and the file's default role."""

    id: PersonId
    role: Role
    name: PersonName | None = None
    token_sha256: TokenHash | None = None

    @property
    def known(self) -> bool:
        return self.name is not None

    @property
    def shown(self) -> str:
        """How a log or a page names the person: their name, else their id."""
        return self.name or self.id


class People(msgspec.Struct, frozen=True, forbid_unknown_fields=True, dict=True):
    """The users file: the people listed, and the role of everyone else."""

    users: list[Person] = []
    default_role: Role = "viewer"

    def validate(self) -> People:
        """Check what spans entries (an id or a token used twice); return self."""
        _unique([(f"users.{i}.id", person.id) for i, person in enumerate(self.users)])
        _unique(
            [
                (f"users.{i}.token_sha256", person.token_sha256)
                for i, person in enumerate(self.users)
                if person.token_sha256 is not None
            ]
        )
        for index, person in enumerate(self.users):
            if person.id == EVERYONE_ELSE:
                raise ProtocolError(
                    f"users.{index}.id", f"{EVERYONE_ELSE!r} means everyone else: set default_role"
                )
            if person.name is None:
                raise ProtocolError(f"users.{index}.name", "is required but missing")
        return self

    @cached_property
    def _by_id(self) -> dict[str, Person]:
        return {person.id: person for person in self.users}

    @cached_property
    def _by_token(self) -> dict[str, Person]:
        return {p.token_sha256: p for p in self.users if p.token_sha256 is not None}

    def person(self, person_id: str) -> Person:
        """The person with this id, or an unknown one with the default role."""
        found = self._by_id.get(person_id)
        if found is not None:
            return found
        return Person(id=person_id, role=self.default_role)

    def signed_in(self, token: str) -> Person | None:
        """The person whose station token this is, or None."""
        digest = token_hash(token)
        for stored, person in self._by_token.items():
            if hmac.compare_digest(stored, digest):
                return person
        return None

    @classmethod
    def from_yaml(cls, text: str | bytes) -> People:
        """The users file's text, checked; a fault is one `ProtocolError` naming the entry."""
        if not text or not str(text).strip():
            raise ProtocolError("users", "the file is empty; it needs users: (and default_role:)")
        try:
            written = msgspec.yaml.decode(text, type=_UsersFile)
        except msgspec.ValidationError as err:
            raise from_validation_error(err) from err
        except msgspec.DecodeError as err:
            raise ProtocolError("users", f"is not valid YAML ({err})") from err
        people = cls(
            users=[
                Person(
                    id=entry.id,
                    name=entry.name,
                    role=_role(f"users.{index}.role", entry.role),
                    token_sha256=entry.token_sha256,
                )
                for index, entry in enumerate(written.users)
            ],
            default_role=_role("default_role", written.default_role),
        )
        return people.validate()


class _Entry(msgspec.Struct, frozen=True, forbid_unknown_fields=True):
    """One person as the file writes them (`role` checked by `_role`)."""

    id: PersonId
    name: PersonName
    role: str
    token_sha256: TokenHash | None = None


class _UsersFile(msgspec.Struct, frozen=True, forbid_unknown_fields=True):
    users: list[_Entry] = []
    default_role: str = "viewer"


def _role(field: str, value: str) -> Role:
    for role in ROLES:
        if role == value:
            return role
    raise ProtocolError(field, f"{value!r} is not a role; roles are {', '.join(ROLES)}")


# Everyone may do everything, as a supervisor: VAHR without a users file.
OPEN = People(users=[], default_role="supervisor")


def load_people(path: str | os.PathLike[str]) -> People:
    """Read and check a users file; a fault is one `ProtocolError` naming the entry."""
    file = os.fspath(path)
    try:
        with open(file, "rb") as stream:  # noqa: PTH123 (as load_fleet: the Lambda's path)
            text = stream.read()
    except OSError as err:
        raise ProtocolError("users", f"cannot read {file}: {err.strerror}") from err
    return People.from_yaml(text)


def _unique(entries: list[tuple[str, str | None]]) -> None:
    first: dict[str, str] = {}
    for field, value in entries:
        if value is None:
            continue
        if value in first:
            raise ProtocolError(field, f"{value!r} is used twice (also {first[value]})")
        first[value] = field
