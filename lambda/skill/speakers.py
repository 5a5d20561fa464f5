"""Who is speaking, and their role: the `People` port and where it reads from.

Alexa names the speaker in every request: `context.System.person.personId` when it
recognised the voice (Alexa personalization), which is preferred, else the account's
`context.System.user.userId`. The role comes from:

- `UsersTable` (`skill.users_table`): the DynamoDB table the stack makes, loaded from a
  users file by `vahr users import`; read on AWS;
- `UsersFile`: a users file read at cold start (`VAHR_USERS_FILE`, `vahr up --users`);
- neither: everyone may do everything, as a supervisor (`vahr.domain.people.OPEN`).

`people_directory(config)` picks one. A directory that cannot be read raises
`skill.errors.PeopleUnavailable`: the skill then sends nothing but a stop, which needs
nobody's role.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any, Protocol

from skill.errors import ConfigError
from vahr.domain.people import OPEN, load_people
from vahr.protocol import ProtocolError

if TYPE_CHECKING:
    from ask_sdk_model import RequestEnvelope

    from skill.config import SkillConfig
    from vahr.domain.people import People, Person

# An envelope that names nobody (hand-built, not Alexa's) is this person, with the default
# role: never anyone's in particular.
NOBODY = "unknown"


class PeopleDirectory(Protocol):
    """Where the skill learns a person's name and role."""

    def person(self, person_id: str) -> Person:
        """The person with this id; someone not listed has no name and the default role.
        Raises PeopleUnavailable when the directory cannot be read."""
        ...


class UsersFile:
    """People from a users file (or any `People`), held in memory."""

    def __init__(self, people: People) -> None:
        self.people = people

    def person(self, person_id: str) -> Person:
        return self.people.person(person_id)


def people_directory(config: SkillConfig) -> PeopleDirectory:
    """The table when the stack names one, else the users file, else everyone open."""
    if config.users_table:
        from skill.users_table import UsersTable  # boto3 is imported only when used

        return UsersTable(config.users_table)
    if config.users_file:
        try:
            return UsersFile(load_people(config.users_file))
        except ProtocolError as err:
            raise ConfigError(f"VAHR_USERS_FILE {config.users_file}: {err}") from err
    return UsersFile(OPEN)


def speaker_id(envelope: RequestEnvelope) -> str:
    """Who is speaking: the recognised person, else the Alexa account."""
    context: Any = envelope.context
    system = getattr(context, "system", None)
    person = getattr(system, "person", None)
    if person is not None and getattr(person, "person_id", None):
        return str(person.person_id)
    user = getattr(system, "user", None)
    if user is not None and getattr(user, "user_id", None):
        return str(user.user_id)
    session_user = getattr(envelope.session, "user", None)
    if session_user is not None and getattr(session_user, "user_id", None):
        return str(session_user.user_id)
    return NOBODY
