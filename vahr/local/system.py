"""The whole system on one machine: the local stack, the Alexa simulator with the skill,
the room assistant robots talk to, the operator station, and one robot-agent process per
robot.

`LocalSystem` is what `vahr up` and `vahr demo` run. It reports each robot event to a
callback (the live lines of `vahr up`) and can wait until every robot is online. The
operator station sits above the local stack (docs/architecture.md), so the system does not
import it: whoever wants one passes `start_station` in (`vahr up` passes
`vahr.station.deployment.on_local_system`), and the system starts it on its broker and its
simulator, in its place among the parts.
"""

from __future__ import annotations

import json
import logging
import shutil
import threading
import time
from collections import deque
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Protocol

import msgspec

from vahr.announce import LowBattery, TaskCancelled
from vahr.assistant import SimulatorAssistant
from vahr.domain.fleet import SPOKEN_LOCALE
from vahr.domain.people import confirmation_on
from vahr.errors import VahrError
from vahr.local.alexa_host import serve_alexa
from vahr.local.announce_host import LocalAnnouncer
from vahr.local.dispatch_host import (
    CHARGE_PATH,
    SERVICE_PATH,
    TASKS_PATH,
    ZONES_PATH,
    LocalDispatcher,
)
from vahr.local.readiness import Readiness
from vahr.local.robots import (
    ProgressRate,
    RobotProcesses,
    SwarmProcess,
    fleet_of,
    generated_fleet,
    write_fleet,
)
from vahr.navigation import load_floor
from vahr.plumbing.mqtt import MqttClient
from vahr.plumbing.ports import ensure_free
from vahr.protocol import Event, ProtocolError, decode_event, decode_presence, topics, utc_now
from vahr.skill_model.generator import build_interaction_model, build_locale_model, render
from vahr.twin import identities
from vahr.twin.shadow_store import ShadowError
from vahr.twin.stack import LocalStack, StackConfig

if TYPE_CHECKING:
    from collections.abc import Callable
    from pathlib import Path

    from vahr.assistant.nlu import InteractionModel
    from vahr.assistant.simulator import AlexaSimulator
    from vahr.dispatch import Task
    from vahr.domain import Fleet
    from vahr.domain.people import People
    from vahr.plumbing.client import Assistant
    from vahr.twin.trail_store import SqliteTrail

log = logging.getLogger(__name__)

ROOM_VOICE = "robot_agent.voice.factories:room"
# How long a start waits for the robots and the assistant before it gives up: a first
# start on a busy 2-core machine (every model learnt, nothing cached yet) took minutes.
READY_TIMEOUT_S = 300.0
# While waiting to be ready, what is awaited is told this often (seconds).
WAIT_NOTICE_S = 10.0
# Robots named in what the system waits for; the rest are counted.
AWAITED_NAMED = 6
# A part that dies more often than this is not restarted again: `vahr up` stops and says why.
RESTART_LIMIT = 5
RESTART_WINDOW_S = 60.0


@dataclass(frozen=True, kw_only=True)
class SystemConfig:
    state_dir: Path
    mqtts_port: int
    mqtt_port: int | None
    api_port: int
    # Names the data plane answers to besides the loopback ones (`vahr up --api-host`).
    api_hosts: frozenset[str] = frozenset()
    # The fleet to run (`vahr up --fleet FILE`); None is the bundled fleet.yaml. `robots`
    # then keeps its first N robots, or adds more.
    fleet: Fleet | None = None
    robots: int | None = None
    # `vahr up --swarm N`: N robots of a generated fleet (on `fleet`'s zones) in one
    # `robot-agent swarm` process instead of a process per robot.
    swarm: int | None = None
    sim_speed_factor: float = 1.0
    ack_timeout_s: float | None = None
    voice: bool = True
    log_level: str = "WARNING"
    # The operator station's port on 127.0.0.1 (0: any free port; None: no station).
    station_port: int | None = None
    # How often the robots report progress: "local" (every simulated second) or "aws"
    # (robot-agent's defaults, what a deployment on AWS gets).
    progress: ProgressRate = "local"
    # The language people speak to the simulated Echo (`vahr up --locale`); the robots'
    # own spoken exchange with the assistant stays English (an English recognizer).
    locale: str = "en-US"
    # Who may do what (`vahr up --users FILE`, `vahr.domain.people`): None, everyone may do
    # everything. `people` is that file read; the station signs its operators in with it.
    users_file: Path | None = None
    people: People | None = None
    # Whether fleet-wide commands are confirmed first; None: as the fleet file says, else
    # whenever people are known. The paper's experiment sets False: one-turn commands.
    confirm: bool | None = None


class ServedStation(Protocol):
    """The operator station as the system sees it: where its page is, and how it stops."""

    @property
    def url(self) -> str: ...

    def stop(self) -> None: ...


class StartStation(Protocol):
    """Build the operator station on the system's parts and start it serving on `port`."""

    def __call__(
        self,
        *,
        port: int,
        fleet: Fleet,
        link: MqttClient,
        assistant: Assistant,
        read_shadow: Callable[[str], bytes | None],
        tasks_url: str | None = None,
        locale: str = "en-US",
        people: People | None = None,
        trail: SqliteTrail | None = None,
        model_file: Path | None = None,
    ) -> ServedStation: ...


class LocalSystem:
    """Start everything in order; `stop()` stops it in reverse. A context manager.

    `start_station` builds the operator station when `config.station_port` asks for one.
    """

    def __init__(
        self,
        config: SystemConfig,
        *,
        on_event: Callable[[Event], None] | None = None,
        start_station: StartStation | None = None,
    ) -> None:
        if config.station_port is not None and start_station is None:
            raise ValueError("station_port: a station needs start_station to build it")
        self.config = config
        self.start_station = start_station
        self.on_event = on_event
        if config.swarm is not None:
            self.fleet: Fleet = generated_fleet(config.swarm, config.fleet)
        else:
            self.fleet = fleet_of(config.robots, config.fleet)
        self.readiness = Readiness(self._awaiting)
        # A fleet on a map: the map read and the fleet checked against it before anything
        # starts, so a bad map stops `vahr up` in one line (vahr.navigation.MapError).
        load_floor(self.fleet)
        self.stack = LocalStack(
            StackConfig(
                state_dir=config.state_dir,
                mqtts_port=config.mqtts_port,
                mqtt_port=config.mqtt_port,
                api_port=config.api_port,
                api_hosts=config.api_hosts,
            ),
            awaiting=self.readiness.awaiting,
        )
        self.robots: RobotProcesses | SwarmProcess | None = None
        self.alexa: AlexaSimulator | None = None
        self._watcher: MqttClient | None = None
        self.announcer: LocalAnnouncer | None = None
        self.dispatcher: LocalDispatcher | None = None
        self._room: Any = None
        self._room_client: MqttClient | None = None
        self._station_client: MqttClient | None = None
        self.station: ServedStation | None = None
        self._spoken_model: Path | None = None
        self._online: dict[str, bool] = {}
        self._changed = threading.Condition()
        self._restarts: dict[str, deque[float]] = {}
        self._room_model: InteractionModel | None = None

    @property
    def confirmation(self) -> bool:
        """Whether the skill confirms fleet-wide commands first (as it decides it)."""
        rules = self.fleet.confirmation_rules
        return confirmation_on(
            self.config.confirm, rules.enabled, self.config.users_file is not None
        )

    @property
    def voice_enabled(self) -> bool:
        return self.config.voice and shutil.which("espeak-ng") is not None

    def endpoints(self) -> dict[str, str | None]:
        """What `vahr up --json` prints first (docs/local.md)."""
        assert self.stack.ca is not None
        station = self.station.url if self.station is not None else None
        return {
            "api": self.stack.api_url,
            "mqtt": self.stack.mqtt_url,
            "mqtts": self.stack.mqtts_url,
            "ca": str(self.stack.ca.ca_file),
            "station": station,
            # The page `vahr up` served before the station, kept as another name for it.
            "dashboard": station,
        }

    def start(self) -> LocalSystem:
        cfg = self.config
        # The simulator understands the names of the fleet it runs: its interaction model is
        # generated from that fleet (skill-package/ holds the bundled fleet's). First, as a
        # fleet Alexa would refuse stops the start before anything runs.
        model = (
            build_interaction_model(self.fleet)
            if cfg.locale == SPOKEN_LOCALE
            else build_locale_model(self.fleet, cfg.locale)
        )
        if cfg.station_port:
            # The data plane's port first: a conflict is named the same with or without a station.
            ensure_free(cfg.api_port, "data-plane API")
            ensure_free(cfg.station_port, "operator station")
        try:
            fleet_file = write_fleet(self.fleet, cfg.state_dir / "fleet.yaml")
            model_file = cfg.state_dir / "interaction-model.json"
            model_file.write_text(render(model), encoding="utf-8")
            # Push-to-talk listens in English: the model just written when it is English's.
            self._spoken_model = model_file if cfg.locale == SPOKEN_LOCALE else None
            self.stack.start()
            self.alexa = serve_alexa(
                self.stack,
                ack_timeout_s=cfg.ack_timeout_s,
                model_file=model_file,
                fleet_file=fleet_file,
                log_level=cfg.log_level,
                locale=cfg.locale,
                readiness=self.readiness,
                users_file=cfg.users_file,
                confirm=cfg.confirm,
            )
            assert self.stack.dataplane is not None and self.stack.ca is not None
            self.stack.dataplane.local_routes[("GET", "/vahr/status")] = self._status
            self.stack.dataplane.local_routes[("GET", "/vahr/fleet")] = self._fleet_route
            self._watcher = MqttClient(
                self.stack.service_endpoint(identities.WATCHER), client_id=identities.WATCHER
            ).connect()
            self._watcher.subscribe(topics.ALL_EVENTS, self._on_event)
            self._watcher.subscribe(topics.ALL_PRESENCE, self._on_presence)
            self._start_announcer()
            self._start_dispatcher()
            if self.voice_enabled:
                self._start_room()
            if cfg.station_port is not None:
                self._start_station(cfg.station_port)
            if cfg.swarm is not None:
                self.robots = SwarmProcess(
                    fleet_file=fleet_file,
                    count=cfg.swarm,
                    credentials=self.stack.ca.service_credentials(identities.SWARM),
                    mqtts_port=cfg.mqtts_port,
                    state_dir=cfg.state_dir / "swarm",
                    sim_speed_factor=cfg.sim_speed_factor,
                    log_level="INFO" if cfg.log_level == "DEBUG" else "WARNING",
                ).start()
            else:
                self.robots = RobotProcesses(
                    fleet_file=fleet_file,
                    things=list(self.fleet.robot_things),
                    ca=self.stack.ca,
                    mqtts_port=cfg.mqtts_port,
                    state_dir=cfg.state_dir / "robots",
                    sim_speed_factor=cfg.sim_speed_factor,
                    voice=ROOM_VOICE if self.voice_enabled else None,
                    log_level="INFO" if cfg.log_level == "DEBUG" else "WARNING",
                    progress=cfg.progress,
                ).start()
        except BaseException:
            self.stop()
            raise
        return self

    def _start_announcer(self) -> None:
        """Robots' troubles told unprompted (`GET /vahr/announcements`); the running speed
        factor on `GET /vahr/health`, so a rehearsal against this stack can adopt it."""
        from vahr.twin.fault_injection import FaultInjector

        dataplane = self.stack.dataplane
        assert dataplane is not None and self._watcher is not None
        self.announcer = LocalAnnouncer(
            self.stack.service_endpoint(identities.ANNOUNCER), self.fleet, locale=self.config.locale
        ).start()
        dataplane.local_routes[("GET", "/vahr/announcements")] = self.announcer.announcer.route
        dataplane.local_routes[("POST", "/vahr/fault")] = FaultInjector(
            self._watcher, self.fleet
        ).route
        dataplane.health["sim_speed_factor"] = self.config.sim_speed_factor

    def _start_dispatcher(self) -> None:
        """Fleet dispatch (`/vahr/tasks`): tasks without a robot's name, over the local
        fleet index, queued in the state directory. Before the robots start, so their
        first shadow updates already reach it."""
        dataplane, store = self.stack.dataplane, self.stack.store
        assert dataplane is not None and store is not None
        announcer = self.announcer.announcer if self.announcer is not None else None

        def given_up(task: Task) -> None:
            # A task whose robot was sent elsewhere by name is told, not dropped silently.
            if announcer is not None and task.thing is not None:
                announcer.observe(
                    [TaskCancelled(task.id, task.thing, task.kind, task.zone, utc_now())]
                )

        def charging(task: Task) -> None:
            # A robot the dispatcher sends to charge by itself is told: it leaves its work.
            if announcer is not None and task.thing is not None:
                announcer.observe([LowBattery(task.thing, utc_now(), zone=task.zone)])

        self.dispatcher = LocalDispatcher(
            fleet=self.fleet,
            index=store.index,
            endpoint=self.stack.service_endpoint(identities.DISPATCHER),
            state_dir=self.config.state_dir,
            on_given_up=given_up,
            on_charging=charging,
            record=self.stack.trail.append if self.stack.trail is not None else None,
        ).start()
        dataplane.typed_routes[TASKS_PATH] = self.dispatcher.api.respond
        dataplane.typed_routes[ZONES_PATH] = self.dispatcher.zones_api.respond
        dataplane.typed_routes[SERVICE_PATH] = self.dispatcher.robots_api.respond
        dataplane.typed_routes[CHARGE_PATH] = self.dispatcher.robots_api.respond

    def _start_room(self) -> None:
        """The assistant robots talk to: a second simulated Echo on the same skill."""
        from vahr.assistant.nlu import InteractionModel
        from vahr.assistant.simulator import AlexaSimulator
        from vahr.local.room_assistant import offline_room_assistant

        assert self.alexa is not None
        model = self.alexa.model
        if self.config.locale != SPOKEN_LOCALE:
            # Robots ask in English whatever the people speak: the room's Echo is English.
            model = InteractionModel(build_interaction_model(self.fleet), background=True)
            self._room_model = model
        from vahr.assistant.envelope import Identity

        # Another Echo (its own user and device) of the same skill.
        room_echo = AlexaSimulator(
            model, self.alexa.handler, identity=Identity(self.alexa.identity.skill_id)
        )

        def ask(request: str) -> str | None:
            turn = room_echo.say(f"alexa {request}", origin="robot")
            # Each question is one-shot: the robot does not hold a conversation.
            room_echo.end_session()
            return turn.speech or None

        self._room_client = MqttClient(
            self.stack.service_endpoint(identities.ROOM), client_id=identities.ROOM
        ).connect()
        self._room = offline_room_assistant(self._room_client, ask).start()

    def _start_station(self, port: int) -> None:
        """The operator station on this stack: the simulator in-process, shadows read from
        the store, every turn seen on the broker, the task queue from the dispatcher."""
        assert self.start_station is not None
        assert self.alexa is not None and self.stack.dataplane is not None
        self._station_client = MqttClient(
            self.stack.service_endpoint(identities.STATION), client_id=identities.STATION
        ).connect()
        self.station = self.start_station(
            port=port,
            fleet=self.fleet,
            link=self._station_client,
            assistant=SimulatorAssistant(self.alexa),
            read_shadow=self._stored_shadow,
            tasks_url=self.stack.api_url + TASKS_PATH if self.dispatcher is not None else None,
            locale=self.config.locale,
            people=self.config.people,
            trail=self.stack.trail,
            model_file=self._spoken_model,
        )
        self.stack.dataplane.redirects["/vahr/dashboard"] = self.station.url

    def _stored_shadow(self, thing: str) -> bytes | None:
        store = self.stack.store
        try:
            return json.dumps(store.get(thing)).encode() if store is not None else None
        except ShadowError:  # not reported yet
            return None

    def wait_online(self, timeout_s: float = 30.0) -> None:
        """Block until every robot said it is online, or raise naming those that did not."""
        deadline = time.monotonic() + timeout_s
        with self._changed:
            while True:
                missing = [t for t in self.fleet.robot_things if not self._online.get(t)]
                if not missing:
                    return
                self._check_exits(missing)
                remaining = deadline - time.monotonic()
                if remaining <= 0:
                    raise VahrError(
                        f"robots not online within {timeout_s:.0f} s: {', '.join(missing)} "
                        f"(logs in {self.config.state_dir / 'robots'})"
                    )
                self._changed.wait(min(remaining, 0.5))

    def wait_ready(
        self,
        timeout_s: float = READY_TIMEOUT_S,
        *,
        on_wait: Callable[[list[str]], None] | None = None,
    ) -> None:
        """Block until the system can take a command (every robot online, the assistant
        able to answer), or raise VahrError naming what it still waited for. `on_wait` is
        told what is awaited every `WAIT_NOTICE_S` seconds while waiting."""
        deadline = time.monotonic() + timeout_s
        notice = time.monotonic() + WAIT_NOTICE_S
        while True:
            if self.readiness.wait(min(max(0.0, deadline - time.monotonic()), 0.5)):
                log.info(
                    "ready: %s robots online, the assistant answers",
                    f"{len(self.fleet.robot_things):,}",
                )
                return
            # A robot that exits, or a model that failed, is said at once.
            with self._changed:
                self._check_exits([t for t in self.fleet.robot_things if not self._online.get(t)])
            self._check_models()
            if time.monotonic() >= deadline:
                raise VahrError(
                    f"not ready within {timeout_s:.0f} s: still waiting for "
                    f"{'; '.join(self.readiness.awaiting())} (logs in {self.config.state_dir})"
                )
            if on_wait is not None and time.monotonic() >= notice:
                on_wait(self.readiness.awaiting())
                notice = time.monotonic() + WAIT_NOTICE_S

    def _check_exits(self, missing: list[str]) -> None:
        """Raise VahrError naming a robot of `missing` whose process exited (or the swarm's,
        which runs every robot), with its last log line."""
        exited = self.robots.exited() if self.robots else {}
        for thing in [*missing, SwarmProcess.SWARM]:
            if thing in exited and self.robots is not None:
                raise VahrError(
                    f"robot {thing} exited with code {exited[thing]}: "
                    f"{self.robots.last_log_line(thing)}"
                )

    def _awaiting(self) -> list[str]:
        """What the system still waits for before it can take a command, in words."""
        awaiting = []
        with self._changed:
            offline = [t for t in self.fleet.robot_things if not self._online.get(t)]
        if offline:
            named = ", ".join(offline[:AWAITED_NAMED])
            more = len(offline) - AWAITED_NAMED
            awaiting.append(
                f"robots to come online: {named}" + (f" and {more:,} more" if more > 0 else "")
            )
        models = [self.alexa.model if self.alexa is not None else None, self._room_model]
        if self.alexa is None or any(m is not None and not m.ready for m in models):
            awaiting.append("the assistant to learn the fleet's names")
        return awaiting

    def _check_models(self) -> None:
        """Raise VahrError when a language model failed to build (it will never be ready)."""
        for model in (self.alexa.model if self.alexa else None, self._room_model):
            if model is not None and model.ready:
                model.wait_ready(0)

    def supervise(self) -> list[str]:
        """Restart the broker or a robot whose process died; one line for each restart.

        A lab runs `vahr up` all day: a robot-agent killed by the OOM killer or a crashed
        mosquitto comes back as a robot's service manager or a broker's would bring it back.
        The broker restarts on the same persistence, so robots resume their sessions and
        commands queued for them; a robot restarts on the same state directory, so a command
        it died running is reported failed (robot_agent.core.in_flight). Raises VahrError
        when one part keeps dying (RESTART_LIMIT times in RESTART_WINDOW_S).
        """
        lines: list[str] = []
        broker = self.stack.broker
        code = broker.exit_code() if broker is not None else None
        if broker is not None and code is not None:
            self._count_restart("the MQTT broker", code)
            broker.restart()
            lines.append(f"the MQTT broker stopped unexpectedly (exit code {code}); restarted it")
        exited = self.robots.exited() if self.robots is not None else {}
        for thing, code in exited.items():
            assert self.robots is not None
            self._count_restart(f"robot {thing}", code)
            self.robots.restart(thing)
            lines.append(f"robot {thing} stopped unexpectedly (exit code {code}); restarted it")
        return lines

    def _count_restart(self, part: str, code: int) -> None:
        now = time.monotonic()
        recent = self._restarts.setdefault(part, deque())
        while recent and now - recent[0] > RESTART_WINDOW_S:
            recent.popleft()
        if len(recent) >= RESTART_LIMIT:
            raise VahrError(
                f"{part} stopped unexpectedly (exit code {code}) {len(recent) + 1} times within "
                f"{RESTART_WINDOW_S:g} s; not restarting it (logs in {self.config.state_dir})"
            )
        recent.append(now)

    def _on_event(self, topic: str, payload: bytes) -> None:
        # A robot's event is a message AWS IoT would bill for, like any other publish.
        self.stack.meter.message("mqtt.robot.event", len(payload))
        try:
            event = decode_event(payload)
        except ProtocolError as err:
            log.warning("malformed event on %s: %s", topic, err)
            return
        if self.on_event is not None:
            self.on_event(event)

    def _on_presence(self, topic: str, payload: bytes) -> None:
        parsed = topics.parse_robot_topic(topic)
        if parsed is None:
            return
        try:
            online = decode_presence(payload).online
        except ProtocolError:
            return
        with self._changed:
            self._online[parsed[0]] = online
            self._changed.notify_all()

    def _status(self, request: dict[str, Any]) -> tuple[int, dict[str, Any]]:
        store = self.stack.store
        robots: dict[str, Any] = {}
        for thing in self.fleet.robot_things:
            try:
                robots[thing] = store.get(thing)["state"].get("reported") if store else None
            except ShadowError:  # not reported yet
                robots[thing] = None
        return 200, {"robots": robots, "online": dict(self._online)}

    def _fleet_route(self, request: dict[str, Any]) -> tuple[int, dict[str, Any]]:
        """The fleet this system runs, as fleet.yaml's keys: what a command given this
        stack's `--api` learns the robots, zones and floor from."""
        return 200, {"fleet": msgspec.to_builtins(self.fleet)}

    def stop(self) -> None:
        # The announcer goes first: robots going offline because the whole system stops is
        # no news to announce (a swarm of 1,000 logged a dropped announcement for each).
        if self.announcer is not None:
            self.announcer.stop()
            self.announcer = None
        if self.robots is not None:
            self.robots.stop()
            self.robots = None
        if self._room is not None:
            self._room.stop()
            self._room = None
        if self.station is not None:
            self.station.stop()
            self.station = None
        if self.dispatcher is not None:
            self.dispatcher.stop()
            self.dispatcher = None
        for client in (self._room_client, self._watcher, self._station_client):
            if client is not None:
                client.stop()
        self._room_client = self._watcher = self._station_client = None
        self.stack.stop()

    def __enter__(self) -> LocalSystem:
        return self.start()

    def __exit__(self, *exc: object) -> None:
        self.stop()
