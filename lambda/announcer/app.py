"""The announcer's Lambda handler: robot events and presence in (from the IoT topic rule),
Alexa notifications out. Thin: parse, run `announce`, report.

The rule's SQL (infra/constructs/announcer.py) gives each event as the robot sent it plus
`sender` (the thing named by the topic), and each presence as `{"online", "at",
"sender"}`. Each announcement Alexa accepted is published on `vahr/assistant/announcements`
for the operator station. An EventBridge schedule also invokes it once a minute (`"source":
"aws.events"`): nothing happened, but time passed, so what the rate limit held back is told
without waiting for the next robot event. The dispatcher function invokes it (asynchronously)
with `{"lost_task": ...}` (`vahr.protocol.lost_tasks.LostTask`) for a fleet task it could
not see through, told as a `cancelled` announcement, and with `{"gone_to_charge": ...}` for a
robot it sent to charge by itself, told as `battery_low`. A malformed message is logged and skipped
(retrying cannot mend it); a failure to deliver raises `AnnouncerError`, so Lambda retries
the event and then dead-letters it. The state is written only when it changed.
"""

from __future__ import annotations

import logging
from datetime import UTC, datetime
from functools import cache
from typing import TYPE_CHECKING, Any

import msgspec

from announcer.aws import AnnouncementTopic, SkillCredentials, StateStore
from announcer.config import AnnouncerConfig
from announcer.errors import AnnouncerError, DeliveryFailed, StateConflict
from announcer.proactive_events import ProactiveEvents
from vahr.announce import (
    AnnouncePolicy,
    LowBattery,
    TaskCancelled,
    signals_from_event,
    signals_from_presence,
)
from vahr.announce.speech import Names
from vahr.domain import load_fleet
from vahr.protocol import Event, Presence, ProtocolError
from vahr.protocol.lost_tasks import (
    GONE_TO_CHARGE_KEY,
    LOST_TASK_KEY,
    gone_to_charge_from,
    lost_task_from,
)

if TYPE_CHECKING:
    from collections.abc import Callable

    from vahr.announce import Signal

log = logging.getLogger("announcer")
# How often a save that lost a race is tried again with the state read anew.
SAVE_ATTEMPTS = 3
# An EventBridge scheduled event's source and detail type.
SCHEDULE = ("aws.events", "Scheduled Event")


def utc_now() -> datetime:
    """The runtime's clock: the time now, in UTC."""
    return datetime.now(UTC)


class Runtime(msgspec.Struct, frozen=True, kw_only=True, dict=True):
    config: AnnouncerConfig
    names: Names
    store: Any
    alexa: Any
    topic: Any
    # What the policy's rate windows and ages are measured by (a test's own clock).
    clock: Callable[[], datetime] = utc_now


@cache
def runtime() -> Runtime:
    """Built once per cold start: configuration, fleet names, adapters."""
    config = AnnouncerConfig.from_env()
    # The policy logs what it does not tell (cleared before its turn, dropped past its bound).
    for name in ("announcer", "vahr.announce"):
        logging.getLogger(name).setLevel(config.log_level)
    return Runtime(
        config=config,
        names=Names.of(load_fleet()),
        store=StateStore(config.table),
        alexa=ProactiveEvents(
            token_url=config.token_url,
            events_url=config.events_url,
            credentials=SkillCredentials(config.secret),
        ),
        topic=AnnouncementTopic(config.iot_data_endpoint),
    )


def lambda_handler(event: dict[str, Any], context: object) -> dict[str, Any]:
    try:
        return announce(event, runtime())
    except AnnouncerError as err:
        log.error("announcement not delivered: %s", err)
        raise
    except Exception as err:  # a bug: still one line in the log, still retried
        log.exception("announcer failed")
        raise AnnouncerError(f"announcer failed: {type(err).__name__}: {err}") from err


def is_tick(message: dict[str, Any]) -> bool:
    """The once-a-minute schedule: no robot said anything, but time passed."""
    return (message.get("source"), message.get("detail-type")) == SCHEDULE


def signals_of(message: dict[str, Any]) -> list[Signal]:
    """What the rule delivered, as the policy's signals; [] for a tick and for what is not
    understood."""
    if is_tick(message):
        return []
    if LOST_TASK_KEY in message:
        try:
            lost = lost_task_from(message[LOST_TASK_KEY])
        except ProtocolError as err:
            log.warning("ignoring a malformed lost task: %s", err)
            return []
        return [TaskCancelled(lost.task, lost.thing, lost.kind, lost.zone, lost.at, lost.why)]
    if GONE_TO_CHARGE_KEY in message:
        try:
            gone = gone_to_charge_from(message[GONE_TO_CHARGE_KEY])
        except ProtocolError as err:
            log.warning("ignoring a malformed robot gone to charge: %s", err)
            return []
        return [LowBattery(gone.thing, gone.at, zone=gone.zone)]
    sender = message.get("sender")
    try:
        if "online" in message:
            presence = msgspec.convert(
                {"online": message.get("online"), "at": message.get("at")}, Presence, strict=False
            )
            return signals_from_presence(str(sender), presence) if sender else []
        event = msgspec.convert(
            {k: v for k, v in message.items() if k != "sender"}, Event, strict=False
        )
    except msgspec.ValidationError as err:
        log.warning("ignoring a malformed message from %s: %s", sender, err)
        return []
    if sender is not None and sender != event.thing:
        log.warning("ignoring an event for %s sent on %s's topic", event.thing, sender)
        return []
    return signals_from_event(event)


def announce(message: dict[str, Any], rt: Runtime) -> dict[str, Any]:
    """Decide on one message and deliver what is due; the state is saved only after every
    announcement was accepted, so a retry decides again (and Alexa drops the duplicates)."""
    signals = signals_of(message)
    for attempt in range(1, SAVE_ATTEMPTS + 1):
        state, version = rt.store.load()
        before = msgspec.json.encode(state)
        policy = AnnouncePolicy(rt.config.settings, rt.names, rt.clock, state)
        told = policy.observe(signals)
        for announcement in told:
            urgent = announcement.priority >= rt.config.settings.urgent_priority
            outcome = rt.alexa.send(
                announcement, creator=rt.names.robot(announcement.thing), urgent=urgent
            )
            # Once Alexa has it: a retry after a failed publish is a duplicate (409) there,
            # and the station knows a repeated announcement by its id.
            rt.topic.publish(announcement)
            log.info("announced %s (%s): %s", announcement.id, outcome, announcement.speech)
        try:
            # Most ticks find nothing to tell: they cost a read, not a write.
            if msgspec.json.encode(policy.state) != before:
                rt.store.save(policy.state, version)
        except StateConflict:
            if attempt == SAVE_ATTEMPTS:
                raise
            continue
        state = policy.state
        return {
            "told": [a.id for a in told],
            "held": state.held,
            "withdrawn": state.withdrawn,
            "dropped": state.dropped,
        }
    raise DeliveryFailed("unreachable")  # pragma: no cover
