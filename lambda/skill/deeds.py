"""What one request did, noted as it happens, for its record in the audit trail.

The skill's request interceptor opens a `Deeds` for each request (`begin`); the places that
reach the robots note what they sent (`skill.robots.Robots.send`, the task desk), the
guard notes a question asked, and a failure is noted where it is caught. The trail's
interceptor (`skill.guard`) then writes one record from them. Each request runs in a
context of its own (`skill.app`), so two requests never share their deeds.
"""

from __future__ import annotations

from contextvars import ContextVar
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

from skill.vocabulary import FLEET

if TYPE_CHECKING:
    from skill.commands import Publication
    from vahr.dispatch import Submission, Task, ZoneChange

# A command to a larger fleet is recorded as going to "all" rather than to every name.
ROBOTS_LISTED_MAX = 100


@dataclass
class Deeds:
    """The commands this request sent and the robots they went to, in order."""

    commands: list[str] = field(default_factory=list)
    robots: list[str] = field(default_factory=list)
    # A yes was asked for before anything is sent.
    asked: bool = False
    # Why the request could not be carried out, if it could not.
    failure: str | None = None
    # The fleet's service changed (a zone closed or opened) though no command was sent.
    changed: bool = False

    @property
    def sent(self) -> bool:
        return bool(self.commands) or self.changed

    def add(self, command_id: str, robots: list[str] | tuple[str, ...]) -> None:
        self.commands.append(command_id)
        for thing in robots:
            if thing not in self.robots:
                self.robots.append(thing)


_current: ContextVar[Deeds | None] = ContextVar("skill_deeds", default=None)


def begin() -> Deeds:
    """A fresh record of deeds for the request under way."""
    deeds = Deeds()
    _current.set(deeds)
    return deeds


def current() -> Deeds:
    """This request's deeds (a fresh one when no request opened any: a tool calling the
    skill's parts directly)."""
    deeds = _current.get()
    return deeds if deeds is not None else begin()


def published(item: Publication) -> None:
    recipients = item.recipients
    if item.to_fleet and len(recipients) > ROBOTS_LISTED_MAX:
        recipients = (FLEET,)
    current().add(item.command.id, recipients)


def submitted(submission: Submission) -> None:
    """An order the dispatcher took: its tasks (each task's id is its command's), and the
    robots given one now."""
    deeds = current()
    for task in [*submission.assigned, *submission.queued]:
        deeds.add(task.id, [task.thing] if task.thing else [])


def cancelled_task(task: Task) -> None:
    current().add(task.id, [task.thing] if task.thing else [])


def zone_changed(change: ZoneChange) -> None:
    """A zone closed or opened; the queued tasks its opening gave to robots are sent."""
    done = current()
    done.changed = True
    for task in change.given:
        done.add(task.id, [task.thing] if task.thing else [])


def failed(reason: str) -> None:
    current().failure = reason


def asked() -> None:
    current().asked = True
