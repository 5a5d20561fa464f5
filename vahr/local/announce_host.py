"""The local announcer: the announcement policy on `vahr up`'s broker.

`Announcer` knows no transport: robot event and presence payloads go in (`on_event`,
`on_presence`), the policy (`vahr.announce`) decides, and each announcement is kept in a
bounded history (`GET /vahr/announcements`, newest last, with how many the rate limit held
back, how many of those cleared before their turn and how many were dropped), published on
`vahr/assistant/announcements` and handed to every listener (`add_listener`: the operator
station's server side subscribes here). A tick thread tells what the rate limit held back
as soon as it may. `LocalAnnouncer` connects it to the broker with the service identity.
"""

from __future__ import annotations

import logging
import threading
from collections import deque
from typing import TYPE_CHECKING, Any

from vahr.announce import (
    AnnouncePolicy,
    AnnounceSettings,
    signals_from_event,
    signals_from_presence,
)
from vahr.announce.speech import Names
from vahr.plumbing.mqtt import MqttClient
from vahr.protocol import ProtocolError, decode_event, decode_presence, encode, topics, utc_now
from vahr.protocol.announcements import announcement_json
from vahr.twin import identities

if TYPE_CHECKING:
    from collections.abc import Callable, Iterable
    from datetime import datetime

    from vahr.announce import Signal
    from vahr.domain import Fleet
    from vahr.plumbing.mqtt import MqttEndpoint
    from vahr.protocol.announcements import Announcement

log = logging.getLogger(__name__)

TICK_S = 0.25


class Announcer:
    """The policy, its history and its listeners; thread-safe; no transport."""

    def __init__(
        self,
        fleet: Fleet,
        settings: AnnounceSettings | None = None,
        *,
        clock: Callable[[], datetime] = utc_now,
        publish: Callable[[Announcement], None] | None = None,
        locale: str = "en-US",
    ) -> None:
        """Announcements are said in `locale`, the language people speak to the assistant."""
        self.settings = settings or AnnounceSettings()
        self._policy = AnnouncePolicy(self.settings, Names.of(fleet, locale), clock)
        self._history: deque[Announcement] = deque(maxlen=self.settings.history)
        self._listeners: list[Callable[[Announcement], None]] = []
        self._publish = publish
        self._lock = threading.Lock()

    def add_listener(self, listener: Callable[[Announcement], None]) -> Callable[[], None]:
        """Call `listener` with every announcement from now on; returns its remover."""
        with self._lock:
            self._listeners.append(listener)

        def remove() -> None:
            with self._lock:
                if listener in self._listeners:
                    self._listeners.remove(listener)

        return remove

    def history(self) -> list[Announcement]:
        with self._lock:
            return list(self._history)

    def on_event(self, topic: str, payload: bytes) -> None:
        try:
            event = decode_event(payload)
        except ProtocolError as err:
            log.debug("announcer: ignoring a malformed event on %s: %s", topic, err)
            return
        self.observe(signals_from_event(event))

    def on_presence(self, topic: str, payload: bytes) -> None:
        parsed = topics.parse_robot_topic(topic)
        try:
            presence = decode_presence(payload)
        except ProtocolError as err:
            log.debug("announcer: ignoring a malformed presence on %s: %s", topic, err)
            return
        if parsed is not None:
            self.observe(signals_from_presence(parsed[0], presence))

    def observe(self, signals: Iterable[Signal]) -> list[Announcement]:
        """Feed signals (a fleet queue's `Queued`/`Dispatched` too); returns what was told."""
        signals = list(signals)
        if not signals:
            return []
        with self._lock:
            told = self._policy.observe(signals)
        self._tell(told)
        return told

    def tick(self) -> list[Announcement]:
        with self._lock:
            told = self._policy.tick()
        self._tell(told)
        return told

    def counts(self) -> dict[str, int]:
        """Announcements held back by the rate limit, withdrawn (cleared before their turn)
        and dropped (more than `max_held` waiting), since the start."""
        with self._lock:
            state = self._policy.state
            return {"held": state.held, "withdrawn": state.withdrawn, "dropped": state.dropped}

    def route(self, request: dict[str, Any]) -> tuple[int, dict[str, Any]]:
        """`GET /vahr/announcements`: the history, newest last, and the counts."""
        return 200, {
            "announcements": [announcement_json(a) for a in self.history()],
            **self.counts(),
        }

    def _tell(self, told: list[Announcement]) -> None:
        if not told:
            return
        with self._lock:
            self._history.extend(told)
            listeners = list(self._listeners)
        for announcement in told:
            log.info("announced: %s", announcement.speech)
            if self._publish is not None:
                try:
                    self._publish(announcement)
                except Exception:  # the broker may be restarting; history and listeners have it
                    log.warning("could not publish an announcement", exc_info=True)
            for listener in listeners:
                try:
                    listener(announcement)
                except Exception:  # a listener's bug must not silence the others
                    log.exception("announcement listener failed")


class LocalAnnouncer:
    """`Announcer` on the local broker: its own client, subscriptions and tick thread."""

    def __init__(
        self,
        endpoint: MqttEndpoint,
        fleet: Fleet,
        settings: AnnounceSettings | None = None,
        *,
        tick_s: float = TICK_S,
        locale: str = "en-US",
    ) -> None:
        self._client = MqttClient(endpoint, client_id=identities.ANNOUNCER)
        self.announcer = Announcer(fleet, settings, publish=self._publish, locale=locale)
        self._tick_s = tick_s
        self._stopping = threading.Event()
        self._ticker: threading.Thread | None = None

    def _publish(self, announcement: Announcement) -> None:
        self._client.publish(
            topics.ASSISTANT_ANNOUNCEMENTS, encode(announcement), qos=1, wait=False
        )

    def start(self) -> LocalAnnouncer:
        # Retained messages are the past (a robot offline before `vahr up` started): the
        # cloud's topic rule never sees them either.
        self._client.subscribe(topics.ALL_EVENTS, self.announcer.on_event, retained=False)
        self._client.subscribe(topics.ALL_PRESENCE, self.announcer.on_presence, retained=False)
        self._client.connect()
        self._ticker = threading.Thread(target=self._tick, name="announcer-tick", daemon=True)
        self._ticker.start()
        return self

    def _tick(self) -> None:
        while not self._stopping.wait(self._tick_s):
            try:
                self.announcer.tick()
            except Exception:  # keep ticking: the next tick may well succeed
                log.exception("announcer tick failed")

    def stop(self) -> None:
        self._stopping.set()
        if self._ticker is not None:
            self._ticker.join(timeout=5.0)
            self._ticker = None
        self._client.stop()

    def __enter__(self) -> LocalAnnouncer:
        return self.start()

    def __exit__(self, *exc: object) -> None:
        self.stop()
