"""The operator station wired together: feed, controls, assistant, push-to-talk and server.

`Station` takes an MQTT client to the deployment's broker (the local stack's, or AWS IoT
Core's with an operator certificate), an assistant, and a way to read a robot's shadow at
start-up; it subscribes the feed, reads every robot's shadow once, and serves the page.

- `vahr up` builds one on its own stack: `LocalSystem` calls the builder `vahr up` hands it
  (`vahr.station.deployment.on_local_system`): the simulator in-process, shadows read from
  the store;
- `vahr station` builds one against any deployment (`vahr.station.deployment`).

Given `people`, each person signs in and the panel's orders are checked against their role;
given a `trail`, every order is recorded in it and the pages show its latest records.
"""

from __future__ import annotations

import logging
import os
import shutil
from dataclasses import dataclass
from typing import TYPE_CHECKING

from vahr.plumbing.ports import LOOPBACK
from vahr.station.app import StationApp
from vahr.station.controls import Controls
from vahr.station.desk import Desk
from vahr.station.feed import Feed
from vahr.station.server import ServerTls, StationServer
from vahr.station.task_queue import TaskPoller, ZoneSwitch
from vahr.station.trail_feed import TrailPoller

if TYPE_CHECKING:
    from collections.abc import Callable
    from pathlib import Path

    from vahr.domain import Fleet
    from vahr.domain.people import People
    from vahr.plumbing.client import Assistant
    from vahr.plumbing.mqtt import MqttClient
    from vahr.station.trail_feed import StationTrail
    from vahr.station.voice import PushToTalk

log = logging.getLogger(__name__)

# `VAHR_WHISPER=off` leaves push-to-talk to pocketsphinx alone (no second ear: a smaller,
# quicker station on a machine that has little to spare).
WHISPER_ENV = "VAHR_WHISPER"


@dataclass(frozen=True, kw_only=True)
class StationConfig:
    port: int
    host: str = LOOPBACK
    token: str | None = None
    # Push-to-talk needs the recognizer (pocketsphinx) and the interaction model.
    voice: bool = True
    model_file: Path | None = None
    # The dispatcher's task queue (`GET {api}/vahr/tasks`), relayed to the pages; None: not shown.
    tasks_url: str | None = None
    # HTTPS served here, or the HTTPS address of a reverse proxy in front (server.py).
    tls: ServerTls | None = None
    public_origin: str | None = None
    # The language people speak to the assistant (`vahr up --locale`): the page's words and
    # the robots' and zones' names default to it.
    locale: str = "en-US"


class Station:
    """Start and stop the station; `url` is the page's address."""

    def __init__(
        self,
        config: StationConfig,
        fleet: Fleet,
        *,
        link: MqttClient,
        assistant: Assistant | None,
        read_shadow: Callable[[str], bytes | None] | None = None,
        turns: bool = True,
        feed: Feed | None = None,
        people: People | None = None,
        trail: StationTrail | None = None,
    ) -> None:
        self.config = config
        self.fleet = fleet
        self.link = link
        self.feed = feed or Feed(fleet, locale=config.locale)
        self._read_shadow = read_shadow
        self._turns = turns
        self.desk = Desk(self.feed, self._publish)
        record = trail.append if trail is not None else None
        self.controls = Controls(fleet, self.desk, self._publish, record)
        self.push_to_talk = self._push_to_talk(assistant) if config.voice and assistant else None
        self.tasks = TaskPoller(config.tasks_url, self.feed) if config.tasks_url else None
        self.app = StationApp(
            feed=self.feed,
            controls=self.controls,
            desk=self.desk,
            assistant=assistant,
            push_to_talk=self.push_to_talk,
            synthesize=_espeak() if shutil.which("espeak-ng") else None,
            zones=ZoneSwitch(config.tasks_url, self.tasks) if config.tasks_url else None,
        )
        self.server = StationServer(
            self.app,
            host=config.host,
            port=config.port,
            token=config.token,
            tls=config.tls,
            public_origin=config.public_origin,
            locale=config.locale,
            people=people,
        )
        self.trail = TrailPoller(trail, self.feed) if trail is not None else None

    def _publish(self, topic: str, payload: bytes) -> None:
        self.link.publish(topic, payload, qos=1)

    def _push_to_talk(self, assistant: Assistant) -> PushToTalk:
        from vahr.station.vocabulary import command_recognizer, whisper_prompt
        from vahr.station.voice import PushToTalk

        model_file, fleet = self.config.model_file, self.fleet
        second_ear = None
        if os.environ.get(WHISPER_ENV, "on") != "off":
            from vahr.speech.whisper_stt import WhisperTranscriber

            def second_ear() -> WhisperTranscriber:
                return WhisperTranscriber(whisper_prompt(fleet))

        return PushToTalk(assistant, lambda: command_recognizer(model_file, fleet), second_ear)

    @property
    def url(self) -> str:
        return self.server.url

    def start(self) -> Station:
        try:
            for topic_filter, handler in self.feed.routes(turns=self._turns):
                self.link.subscribe(topic_filter, handler)
            if self._read_shadow is not None:
                for thing in self.fleet.robot_things:
                    document = self._read_shadow(thing)
                    if document is not None:
                        self.feed.load_shadow(thing, document)
            self.server.start()
            if self.tasks is not None:
                self.tasks.start()
            if self.trail is not None:
                self.trail.start()
        except BaseException:
            self.stop()
            raise
        return self

    def stop(self) -> None:
        if self.tasks is not None:
            self.tasks.stop()
        if self.trail is not None:
            self.trail.stop()
        self.server.stop()

    def __enter__(self) -> Station:
        return self.start()

    def __exit__(self, *exc: object) -> None:
        self.stop()


def _espeak() -> Callable[[str], bytes]:
    from vahr.speech.tts import EspeakSynthesizer

    synthesizer = EspeakSynthesizer()

    def synthesize(text: str) -> bytes:
        return synthesizer.synthesize(text).to_wav()

    return synthesize
