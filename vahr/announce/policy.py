"""The announcement policy: robot events, presence and queued tasks in, announcements out.

Pure and clock-injected: `AnnouncePolicy(settings, names, clock)` holds a `PolicyState`
(which faults are open, which were told, when each person was last told something) that
the cloud's announcer function saves between invocations and the local announcer keeps in
memory. The rules:

- a fault opens on `stuck`, on `failed` (with its reason), when presence says offline, and
  when a queued task has waited longer than `queue_wait_s`; a `failed` whose reason starts
  with `stuck:` is the same fault as the `stuck` before it;
- one fault, one announcement: a fault already open is not told again until it clears.
  `stuck` and `failed` clear when the robot takes a new command, stops, arrives or
  finishes; `offline` when it is back online; `waiting` when the task is dispatched;
- per person, at most `max_per_window` announcements in any `window_s`; kinds below
  `urgent_priority` leave `reserve_for_urgent` of the window free;
- nothing is lost silently: what the limit holds back is told later, highest priority
  first, as soon as the window allows (`tick`), however long it waited. Only a fault that
  clears before its turn is not told (a cleared fault is not news), and the log says so.
  At most `max_held` wait at once; past that the last in line is dropped with a warning
  in the log and counted in `PolicyState.dropped`;
- a finished task (`done`, off by default) is told once, like a fault that never clears,
  and so is a task the fleet gave up because its robot was sent elsewhere by name
  (`cancelled`, from the dispatcher's `TaskCancelled`): no task leaves without a word;
- a robot the dispatcher sends to charge because it is low (`LowBattery`) is told once
  (`battery_low`).

There is no fleet task queue yet. `Queued` and `Dispatched` are the signals one will
send (a task id, the robot it is for if any, when it was queued); `tick` tells the tasks
that waited too long.
"""

from __future__ import annotations

import hashlib
import logging
from dataclasses import dataclass
from datetime import UTC, datetime
from typing import TYPE_CHECKING

import msgspec

from vahr.announce.speech import sentence
from vahr.protocol.announcements import Announcement, AnnouncementKind

if TYPE_CHECKING:
    from collections.abc import Callable, Iterable

    from vahr.announce.settings import AnnounceSettings
    from vahr.announce.speech import Names
    from vahr.protocol import Event, Presence

log = logging.getLogger(__name__)

STUCK_PREFIX = "stuck:"
# Events after which a robot that was stuck or failed is no longer so.
_CLEARS_TASK_FAULTS = frozenset({"accepted", "stopped", "done", "arrived"})
_TASK_FAULTS: tuple[AnnouncementKind, ...] = ("stuck", "failed")


# -- signals: what happened, as the policy sees it --------------------------------------


@dataclass(frozen=True)
class Opened:
    """A fault began on `thing` (or, for `waiting`, on the task `subject`)."""

    thing: str | None
    kind: AnnouncementKind
    at: datetime
    reason: str | None = None
    zone: str | None = None
    subject: str | None = None


@dataclass(frozen=True)
class Cleared:
    """These kinds of fault on `thing` are over."""

    thing: str
    kinds: tuple[AnnouncementKind, ...]
    at: datetime


@dataclass(frozen=True)
class Finished:
    """`thing` finished a task."""

    thing: str
    at: datetime
    zone: str | None = None


@dataclass(frozen=True)
class Queued:
    """A fleet queue took task `task` (for `thing`, or any robot) at `at`."""

    task: str
    at: datetime
    thing: str | None = None


@dataclass(frozen=True)
class Dispatched:
    """The queue gave task `task` to a robot (or dropped it): it waits no more."""

    task: str
    at: datetime


@dataclass(frozen=True)
class TaskCancelled:
    """The fleet gave up task `task` that `thing` held: someone sent `thing` elsewhere by
    name (`why` "preempted"), or `thing` went offline or never acknowledged it (`why`
    "offline", "unacknowledged"). `kind` is the task's (`deliver`, `navigate`), `zone`
    where it was going."""

    task: str
    thing: str
    kind: str
    zone: str
    at: datetime
    why: str = "preempted"


@dataclass(frozen=True)
class LowBattery:
    """The dispatcher sent `thing`, low on charge, to the charger `zone` by itself."""

    thing: str
    at: datetime
    zone: str | None = None


Signal = Opened | Cleared | Finished | Queued | Dispatched | TaskCancelled | LowBattery
# Kinds told once and forgotten (nothing clears them: they are news, not a state).
_ONE_SHOT: frozenset[AnnouncementKind] = frozenset({"done", "cancelled", "battery_low"})


def signals_from_event(event: Event) -> list[Signal]:
    """What a robot's event means for the announcer (most events mean nothing)."""
    thing, at = event.thing, event.at
    if event.event == "stuck":
        return [Opened(thing, "stuck", at, reason=event.reason, zone=event.zone)]
    if event.event == "failed":
        reason = event.reason or ""
        if reason.startswith(STUCK_PREFIX):
            # The executor ends a stuck task as failed; that is the same fault.
            stuck = reason[len(STUCK_PREFIX) :].strip()
            return [Opened(thing, "stuck", at, reason=stuck, zone=event.zone)]
        return [Opened(thing, "failed", at, reason=event.reason, zone=event.zone)]
    signals: list[Signal] = []
    if event.event in _CLEARS_TASK_FAULTS:
        signals.append(Cleared(thing, _TASK_FAULTS, at))
    if event.event == "done":
        signals.append(Finished(thing, at, zone=event.zone))
    return signals


def signals_from_presence(thing: str, presence: Presence) -> list[Signal]:
    if presence.online:
        return [Cleared(thing, ("offline",), presence.at)]
    return [Opened(thing, "offline", presence.at, reason="its connection was lost")]


# -- state: what the policy remembers (saved by the cloud's announcer between calls) -----


class Fault(msgspec.Struct, kw_only=True):
    subject: str
    kind: AnnouncementKind
    thing: str | None
    opened_at: float
    # When the announcer learned of it, on its own clock: grace periods and staleness are
    # measured from here, whatever the robot's clock says.
    seen_at: float
    reason: str | None = None
    zone: str | None = None
    # How a `cancelled` task was lost, when not because its robot was sent elsewhere.
    why: str | None = None
    told: bool = False
    # The rate limit held it back at least once (counted once in `PolicyState.held`).
    held: bool = False
    # Dropped from a line longer than `max_held`: never told, but still open, so the same
    # fault again is not told either until it clears.
    dropped: bool = False

    @property
    def pending(self) -> bool:
        return not self.told and not self.dropped


class QueuedTask(msgspec.Struct, kw_only=True):
    task: str
    thing: str | None
    queued_at: float


class PolicyState(msgspec.Struct, kw_only=True):
    faults: list[Fault] = msgspec.field(default_factory=list)
    finished: list[Fault] = msgspec.field(default_factory=list)
    queued: list[QueuedTask] = msgspec.field(default_factory=list)
    # person -> the times (epoch seconds) they were told something within the window.
    told: dict[str, list[float]] = msgspec.field(default_factory=dict)
    # How many announcements the rate limit held back (each counted once), how many of
    # those cleared before their turn (not news any more), and how many were dropped
    # because more than `max_held` waited at once.
    held: int = 0
    withdrawn: int = 0
    dropped: int = 0


class AnnouncePolicy:
    """Decide what to announce; `observe` for signals, `tick` as time passes."""

    def __init__(
        self,
        settings: AnnounceSettings,
        names: Names,
        clock: Callable[[], datetime],
        state: PolicyState | None = None,
    ) -> None:
        self.settings = settings
        self.names = names
        self._clock = clock
        self.state = state or PolicyState()

    def observe(self, signals: Iterable[Signal]) -> list[Announcement]:
        """Apply `signals` in order, then return what is due now."""
        for signal in signals:
            self._apply(signal)
        return self.tick()

    def tick(self) -> list[Announcement]:
        """What is due now: faults held back by the rate limit, tasks that waited too long."""
        now = self._clock()
        seconds = now.timestamp()
        for task in self.state.queued:
            if seconds - task.queued_at > self.settings.queue_wait_s:
                self._open(
                    Opened(task.thing, "waiting", now, subject=task.task), opened_at=task.queued_at
                )
        return self._due(now)

    def open_faults(self) -> list[Fault]:
        return list(self.state.faults)

    # -- applying signals ------------------------------------------------------------------

    def _apply(self, signal: Signal) -> None:
        if isinstance(signal, Opened):
            self._open(signal, opened_at=signal.at.timestamp())
        elif isinstance(signal, Cleared):
            self._clear(
                lambda f: f.thing == signal.thing and f.kind in signal.kinds and f.kind != "waiting"
            )
        elif isinstance(signal, Finished):
            self._tell_once("done", signal.thing, signal)
        elif isinstance(signal, TaskCancelled):
            why = None if signal.why == "preempted" else signal.why
            self._tell_once("cancelled", signal.task, signal, reason=signal.kind, why=why)
            self.state.queued = [t for t in self.state.queued if t.task != signal.task]
        elif isinstance(signal, LowBattery):
            self._tell_once("battery_low", signal.thing, signal)
        elif isinstance(signal, Queued):
            if not any(t.task == signal.task for t in self.state.queued):
                self.state.queued.append(
                    QueuedTask(
                        task=signal.task, thing=signal.thing, queued_at=signal.at.timestamp()
                    )
                )
        else:  # Dispatched
            self.state.queued = [t for t in self.state.queued if t.task != signal.task]
            self._clear(lambda f: f.kind == "waiting" and f.subject == signal.task)

    def _tell_once(
        self,
        kind: AnnouncementKind,
        subject: str,
        signal: Finished | TaskCancelled | LowBattery,
        *,
        reason: str | None = None,
        why: str | None = None,
    ) -> None:
        """Keep a one-off announcement (nothing to clear later) for the next turn, if this
        kind is announced at all."""
        if kind in self.settings.kinds:
            self.state.finished.append(
                Fault(
                    subject=subject,
                    kind=kind,
                    thing=signal.thing,
                    opened_at=signal.at.timestamp(),
                    seen_at=self._clock().timestamp(),
                    reason=reason,
                    zone=signal.zone,
                    why=why,
                )
            )

    def _clear(self, over: Callable[[Fault], bool]) -> None:
        """Forget the faults that are `over`; one not yet told is not news any more."""
        kept: list[Fault] = []
        for fault in self.state.faults:
            if not over(fault):
                kept.append(fault)
            elif fault.pending:
                if fault.held:
                    self.state.withdrawn += 1
                log.info(
                    "not announcing %s %s: it cleared before it was told (%s)",
                    fault.subject,
                    fault.kind,
                    "held back by the rate limit" if fault.held else "still within its grace",
                )
        self.state.faults = kept

    def _open(self, signal: Opened, *, opened_at: float) -> None:
        if signal.kind not in self.settings.kinds:
            return
        subject = signal.subject or signal.thing or "fleet"
        for fault in self.state.faults:
            if fault.subject == subject and fault.kind == signal.kind:
                # Still open: one fault, one announcement. Keep the better reason.
                fault.reason = fault.reason or signal.reason
                fault.zone = fault.zone or signal.zone
                return
        self.state.faults.append(
            Fault(
                subject=subject,
                kind=signal.kind,
                thing=signal.thing,
                opened_at=opened_at,
                seen_at=self._clock().timestamp(),
                reason=signal.reason,
                zone=signal.zone,
            )
        )

    # -- deciding ------------------------------------------------------------------------

    def _in_line(self, faults: Iterable[Fault]) -> list[Fault]:
        """Most urgent first, then the oldest: the order in which they are told."""
        return sorted(
            faults, key=lambda f: (-self.settings.priority(f.kind), f.opened_at, f.subject)
        )

    def _due(self, now: datetime) -> list[Announcement]:
        settings, seconds = self.settings, now.timestamp()
        waiting = [f for f in self.state.faults if f.pending and self._ripe(f, seconds)]
        announcements: list[Announcement] = []
        for fault in self._in_line(waiting + self.state.finished):
            person = settings.person_for(fault.thing)
            told = [t for t in self.state.told.get(person, []) if seconds - t < settings.window_s]
            self.state.told[person] = told
            limit = settings.max_per_window
            if settings.priority(fault.kind) < settings.urgent_priority:
                limit -= settings.reserve_for_urgent
            if len(told) >= limit:
                if not fault.held:
                    fault.held = True
                    self.state.held += 1
                continue
            told.append(seconds)
            if fault.kind in _ONE_SHOT:
                self.state.finished.remove(fault)
            else:
                fault.told = True
            announcements.append(self._announcement(fault, now, person))
        # Forget the send times of people told nothing within the window.
        self.state.told = {p: times for p, times in self.state.told.items() if times}
        self._bound_the_line()
        return announcements

    def _bound_the_line(self) -> None:
        """Keep at most `max_held` waiting to be told: drop the last in line, loudly."""
        untold = [f for f in self.state.faults if f.pending] + self.state.finished
        excess = len(untold) - self.settings.max_held
        if excess <= 0:
            return
        for fault in self._in_line(untold)[-excess:]:
            if fault.kind in _ONE_SHOT:
                self.state.finished.remove(fault)
            else:
                fault.dropped = True
            self.state.dropped += 1
            log.warning(
                "dropped the announcement of %s %s (opened at %s): more than %d were waiting",
                fault.subject,
                fault.kind,
                datetime.fromtimestamp(fault.opened_at, UTC).isoformat(),
                self.settings.max_held,
            )

    def _ripe(self, fault: Fault, seconds: float) -> bool:
        if fault.kind == "offline":
            return seconds - fault.seen_at >= self.settings.offline_grace_s
        return True

    def _announcement(self, fault: Fault, now: datetime, person: str) -> Announcement:
        opened = datetime.fromtimestamp(fault.opened_at, UTC)
        return Announcement(
            id=reference_id(fault.subject, fault.kind, fault.opened_at),
            time=now,
            thing=fault.thing,
            kind=fault.kind,
            priority=self.settings.priority(fault.kind),
            speech=sentence(
                fault.kind,
                self.names,
                thing=fault.thing,
                reason=fault.reason,
                zone=fault.zone,
                waited_s=now.timestamp() - fault.opened_at,
                why=fault.why,
            ),
            reason=fault.reason,
            person=person,
            opened_at=opened,
        )


def reference_id(subject: str, kind: str, opened_at: float) -> str:
    """A stable id for one fault: the same fault told twice (a retry) has the same id, so
    Alexa's Proactive Events API refuses the duplicate (409) instead of notifying twice."""
    digest = hashlib.sha256(f"{subject}\0{kind}\0{opened_at:.6f}".encode()).hexdigest()
    # Alexa's referenceId takes letters, digits and '~' only: `battery_low` is `batterylow`.
    return f"vahr~{kind.replace('_', '')}~{digest[:32]}"
