"""The soak's books: every command sent, every robot's own record of it, and the verdict.

A command is owed to each robot it was addressed to (one robot, or every robot for the
fleet topic). It is settled for that robot when the robot's event log shows it ended:
`done` after exactly one `accepted` (executed once), or `failed`, `cancelled` or `rejected`
with a reason (reported). It is lost when the sender was told it was sent (PUBACK, or the
skill named it) and the robot's log has no end for it; it ran twice when the robot
accepted it more than once. A command whose publish the sender was told failed is not owed;
it must then not run at all (the sender said so to a person).
"""

from __future__ import annotations

import re
import threading
from collections import defaultdict
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from collections.abc import Iterable
    from pathlib import Path

    from vahr.protocol import Event

ENDINGS = ("done", "failed", "cancelled", "rejected")
# `robot_agent.agent` logs each event as "{thing}: {event} {action} {id} [field=value ...]".
_AGENT_LINE = re.compile(
    r" (?:INFO|WARNING) robot_agent\.agent: (?P<thing>\S+): "
    r"(?P<event>accepted|done|failed|cancelled|rejected) (?P<action>\S+) (?P<id>\S+)"
    r"(?: .*?reason=(?P<reason>.*))?$"
)
_AGENT_START = re.compile(r" robot_agent: (?P<thing>\S+): starting \(")


@dataclass(frozen=True)
class Sent:
    """A command as its sender saw it."""

    command_id: str
    action: str
    targets: tuple[str, ...]
    path: str  # "skill", "console" or "shadow" (desired state)
    at: float
    error: str | None = None  # what the sender was told when the publish failed
    # The sender was told the outcome is unknown (no PUBACK in time; the broker may have
    # it): not owed, and it may run, once at most.
    unconfirmed: bool = False


@dataclass
class Record:
    """What one robot did with one command id, in the order it reported it."""

    events: list[tuple[str, str | None]] = field(default_factory=list)

    @property
    def accepted(self) -> int:
        return sum(1 for event, _ in self.events if event == "accepted")

    @property
    def ending(self) -> tuple[str, str | None] | None:
        endings = [(e, r) for e, r in self.events if e in ENDINGS]
        return endings[-1] if endings else None


@dataclass
class Verdict:
    owed: int = 0
    executed: int = 0
    reported: dict[str, int] = field(default_factory=lambda: defaultdict(int))
    reported_without_reason: int = 0
    lost: list[str] = field(default_factory=list)
    run_twice: list[str] = field(default_factory=list)
    # Desired state holds one command: one written while the robot had not yet read an
    # earlier one replaces it, as on AWS (last writer wins). Not lost: the shadow said so.
    replaced_in_desired: int = 0
    refused_at_source: int = 0
    ran_after_refusal: list[str] = field(default_factory=list)
    # Publishes the sender was told may or may not have reached the broker, and of those
    # the ones a robot ran (allowed: the sender was not told they failed).
    unconfirmed: int = 0
    unconfirmed_ran: int = 0
    unknown: list[str] = field(default_factory=list)


class Ledger:
    """Thread-safe books of what was sent and what each robot recorded."""

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self.sent: list[Sent] = []
        self._swarm: dict[tuple[str, str], Record] = defaultdict(Record)
        self.swarm_events = 0

    def send(self, sent: Sent) -> None:
        with self._lock:
            self.sent.append(sent)

    def swarm_event(self, event: Event) -> None:
        """A swarm robot's event, as it published it (called on the swarm's loop)."""
        if event.command_id is None:
            return
        with self._lock:
            self.swarm_events += 1
            self._swarm[(event.thing, event.command_id)].events.append((event.event, event.reason))

    def records(self, agent_logs: Iterable[Path]) -> dict[tuple[str, str], Record]:
        """Every robot's records: the swarm's, and the agents' read from their logs."""
        with self._lock:
            found = {key: Record(list(r.events)) for key, r in self._swarm.items()}
        for path in agent_logs:
            for key, record in read_agent_log(path)[0].items():
                found[key] = record
        return found

    def settled(self, records: dict[tuple[str, str], Record]) -> bool:
        """True when every command owed to a robot has ended in that robot's records."""
        for sent in self.owed():
            for thing in sent.targets:
                record = records.get((thing, sent.command_id))
                if record is None or record.ending is None:
                    return False
        return True

    def owed(self) -> list[Sent]:
        with self._lock:
            return [s for s in self.sent if s.error is None and not s.unconfirmed]

    def verdict(self, records: dict[tuple[str, str], Record]) -> Verdict:
        verdict = Verdict()
        with self._lock:
            sent = list(self.sent)
        known = {s.command_id for s in sent}
        for command in sent:
            ran = [
                records[(t, command.command_id)]
                for t in command.targets
                if (t, command.command_id) in records
            ]
            if command.unconfirmed:
                verdict.unconfirmed += 1
                verdict.unconfirmed_ran += bool(ran)
                verdict.run_twice += [command.command_id for r in ran if r.accepted > 1]
                continue
            if command.error is not None:
                verdict.refused_at_source += 1
                if ran:
                    verdict.ran_after_refusal.append(command.command_id)
                continue
            for thing in command.targets:
                verdict.owed += 1
                label = f"{command.path} {command.action} {command.command_id} -> {thing}"
                record = records.get((thing, command.command_id))
                ending = record.ending if record is not None else None
                if record is not None and record.accepted > 1:
                    verdict.run_twice.append(label)
                if ending is None and _replaced(command, thing, sent, records):
                    verdict.replaced_in_desired += 1
                elif ending is None:
                    verdict.lost.append(label)
                elif ending[0] == "done":
                    verdict.executed += 1
                else:
                    verdict.reported[ending[0]] += 1
                    if not ending[1]:
                        verdict.reported_without_reason += 1
        verdict.unknown = sorted({f"{t} {i}" for t, i in records if i not in known})
        return verdict


def read_agent_log(path: Path) -> tuple[dict[tuple[str, str], Record], tuple[str, str] | None]:
    """A robot-agent's records from its log, and its last command since it last started
    (id, result), which its shadow must show."""
    records: dict[tuple[str, str], Record] = defaultdict(Record)
    last: tuple[str, str] | None = None
    if not path.exists():
        return {}, None
    for line in path.read_text(errors="replace").splitlines():
        if _AGENT_START.search(line):
            last = None  # a new process starts with no last command
            continue
        match = _AGENT_LINE.search(line)
        if match is None:
            continue
        key = (match["thing"], match["id"])
        records[key].events.append((match["event"], match["reason"]))
        last = (match["id"], match["event"])
    return dict(records), last


def _replaced(
    command: Sent, thing: str, sent: list[Sent], records: dict[tuple[str, str], Record]
) -> bool:
    """True when `command`, written as `thing`'s desired state, was overwritten by a later
    desired command that `thing` then ran."""
    if command.path != "shadow":
        return False
    return any(
        later.path == "shadow"
        and later.error is None
        and later.at > command.at
        and thing in later.targets
        and (thing, later.command_id) in records
        for later in sent
    )
