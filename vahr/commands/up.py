"""`vahr up`: run the whole system on this machine until Ctrl-C or SIGTERM."""

from __future__ import annotations

import json
import signal
import sys
import threading
import time
from pathlib import Path
from typing import TYPE_CHECKING

from vahr.cli_router import add_logging_flag, setup_logging
from vahr.commands.fleet_flag import add_fleet_flag, read_fleet_on_its_floor

if TYPE_CHECKING:
    import argparse

    from vahr.domain import Fleet
    from vahr.domain.people import People
    from vahr.local.system import LocalSystem
    from vahr.protocol import Event

DEFAULT_API_PORT = 8180
DEFAULT_STATION_PORT = 8181
DEFAULT_STATE_DIR = Path(".state")
# The plaintext development listener's usual port, when --dev-plaintext opens it.
PLAINTEXT_PORT = 1883
# The banner names at most this many robots; a swarm's are given as a range.
BANNER_ROBOTS = 12
# One command's same event from several robots within this many seconds is one line.
COALESCE_S = 0.5
# That line names this many robots, then counts the rest.
GROUP_NAMED = 3
# Robots a swarm builds and brings online per second, at least (measured: docs/local.md).
SWARM_BUILD_PER_S = 100


def configure(parser: argparse.ArgumentParser) -> None:
    add_fleet_flag(parser)
    parser.add_argument(
        "--robots", type=int, help="the fleet's first N robots, or more (default: all of them)"
    )
    parser.add_argument(
        "--swarm",
        type=int,
        metavar="N",
        help="N simulated robots (rover1..) in one process, on a floor sized for them"
        " (1 to 4,000; the zones are --fleet's)",
    )
    parser.add_argument(
        "--state-dir", type=Path, default=DEFAULT_STATE_DIR, help="local state (default .state)"
    )
    parser.add_argument(
        "--api-port", type=int, default=DEFAULT_API_PORT, help="data-plane API port (default 8180)"
    )
    parser.add_argument(
        "--dev-plaintext",
        action="store_true",
        help="also open the plaintext MQTT listener on 127.0.0.1 (development only: any "
        "program on this machine can then command every robot)",
    )
    parser.add_argument(
        "--mqtt-port",
        type=int,
        help=f"the plaintext listener's port with --dev-plaintext (default {PLAINTEXT_PORT})",
    )
    parser.add_argument("--mqtts-port", type=int, default=8883, help="mTLS MQTT port (8883)")
    parser.add_argument(
        "--api-host",
        action="append",
        default=[],
        metavar="NAME",
        help="a host name the data plane answers to besides 127.0.0.1 and localhost (a "
        "proxy's or a tunnel's); repeat for several",
    )
    parser.add_argument(
        "--station-port",
        type=int,
        default=DEFAULT_STATION_PORT,
        help=f"operator station page on 127.0.0.1 (default {DEFAULT_STATION_PORT}), 0 for none",
    )
    parser.add_argument(
        "--sim-speed-factor", type=float, default=1.0, help="simulated time runs this much faster"
    )
    parser.add_argument(
        "--ack-timeout", type=float, help="seconds the skill waits for acknowledgments"
    )
    parser.add_argument(
        "--no-voice", action="store_true", help="no room assistant (robots cannot ask by voice)"
    )
    parser.add_argument(
        "--users",
        type=Path,
        metavar="FILE",
        help="who may do what: a YAML file of people (Alexa ids), their names and roles "
        "(viewer, operator, supervisor) and default_role; fleet-wide commands are then "
        "confirmed first and the station signs its operators in (default: anyone may do "
        "everything, as today)",
    )
    parser.add_argument(
        "--locale",
        default="en-US",
        help="the language people speak to the simulated Echo: en-US (default) or de-DE "
        "(speech recognition and the robots' voice stay English)",
    )
    parser.add_argument("--json", action="store_true", help="print JSON lines")
    add_logging_flag(parser)
    parser.set_defaults(log_level="WARNING")


def run(args: argparse.Namespace) -> int:
    from vahr.errors import VahrError

    setup_logging(args.log_level)
    from vahr.domain.locale import LocaleError, check_locale, load_language

    try:
        language = load_language(check_locale(args.locale))
    except LocaleError as err:
        raise VahrError(str(err)) from err
    if not language.speech.recognised:
        print(
            f"vahr up: {args.locale} is understood and spoken; speech recognition here is "
            "English only, so push-to-talk and the robots' spoken weather exchange stay English",
            file=sys.stderr,
        )
    mqtt_port = _plaintext_port(args)
    for flag in ("api_port", "mqtts_port", "station_port"):
        value = getattr(args, flag)
        if not 0 <= value <= 65535 or (value == 0 and flag != "station_port"):
            raise VahrError(f"--{flag.replace('_', '-')} {value}: not a usable port")
    if args.sim_speed_factor <= 0:
        raise VahrError("--sim-speed-factor must be more than 0")
    fleet = read_fleet_on_its_floor(args.fleet)
    if args.fleet is not None and args.robots is not None and args.robots > len(fleet.robots):
        # Robots made up past a fleet of one's own would drive among its robots under names
        # nobody gave them (placebot5 in a hospital): a fleet file says what runs.
        raise VahrError(
            f"--robots {args.robots}: {args.fleet} has {len(fleet.robots)} robots; give at most "
            f"{len(fleet.robots)}, or add robots to the file (or use --swarm N)"
        )
    if args.swarm is not None:
        from vahr.local.robots import SWARM_MAX

        if args.robots is not None:
            raise VahrError("give either --robots (a process per robot) or --swarm, not both")
        if not 1 <= args.swarm <= SWARM_MAX:
            raise VahrError(
                f"--swarm {args.swarm}: give 1 to {SWARM_MAX:,} robots (the most whose names"
                " fit in one Alexa interaction model; see docs/large-fleets.md)"
            )
    people = _people(args.users)
    # The system's modules after the flags are checked: a refusal comes without them.
    from vahr.local.system import READY_TIMEOUT_S, LocalSystem, SystemConfig
    from vahr.station.deployment import on_local_system

    config = SystemConfig(
        state_dir=args.state_dir.resolve(),
        mqtts_port=args.mqtts_port,
        mqtt_port=mqtt_port,
        api_port=args.api_port,
        api_hosts=frozenset(args.api_host),
        fleet=fleet,
        robots=args.robots,
        swarm=args.swarm,
        sim_speed_factor=args.sim_speed_factor,
        ack_timeout_s=args.ack_timeout,
        voice=not args.no_voice,
        log_level=args.log_level,
        station_port=args.station_port or None,
        locale=args.locale,
        users_file=args.users.resolve() if args.users is not None else None,
        people=people,
    )
    stopping = threading.Event()
    # SIGTERM ends the run like Ctrl-C does; both just set the event the main thread waits on.
    previous = {
        signum: signal.signal(signum, lambda *_: stopping.set())
        for signum in (signal.SIGINT, signal.SIGTERM)
    }
    printer = _EventPrinter(args.json, progress=args.log_level == "DEBUG")
    system = LocalSystem(config, on_event=printer.print, start_station=on_local_system)
    try:
        system.start()
        if system.stack.recovered:
            print(f"vahr up: recovered: {system.stack.recovered}", file=sys.stderr, flush=True)
        # The endpoints are printed only once the system can take a command: every robot
        # online (a swarm's together, once it has built them all) and the assistant able to
        # answer. A first start learns the fleet's names and the robots' hearing (cached
        # for the next), which on a busy machine takes minutes rather than seconds.
        system.wait_ready(READY_TIMEOUT_S + (args.swarm or 0) / SWARM_BUILD_PER_S, on_wait=_waiting)
        endpoints = system.endpoints()
        if args.json:
            _emit(json.dumps(endpoints))
        else:
            _emit(_banner(endpoints, system.fleet, system.voice_enabled, args.locale, _who(system)))
        printer.release()
        while not stopping.wait(0.5):
            for line in system.supervise():
                print(f"vahr up: {line}", file=sys.stderr, flush=True)
    finally:
        system.stop()
        printer.stop()
        for signum, handler in previous.items():
            signal.signal(signum, handler)
    if not args.json:
        print("vahr up: stopped", file=sys.stderr)
    return 0


def _plaintext_port(args: argparse.Namespace) -> int | None:
    """The plaintext listener's port, or None: it is opened only with --dev-plaintext."""
    from vahr.errors import VahrError

    if not args.dev_plaintext:
        if args.mqtt_port:
            raise VahrError(
                f"--mqtt-port {args.mqtt_port}: the plaintext listener is off; add "
                "--dev-plaintext to open it (any program on this machine can then command "
                "the robots), or connect to --mqtts-port with a certificate"
            )
        return None
    port = PLAINTEXT_PORT if args.mqtt_port is None else args.mqtt_port
    if not 0 < port <= 65535:
        raise VahrError(f"--mqtt-port {port}: not a usable port")
    return int(port)


def _waiting(awaiting: list[str]) -> None:
    print(f"vahr up: starting; waiting for {'; '.join(awaiting)}", file=sys.stderr, flush=True)


def _emit(line: str) -> None:
    print(line, flush=True)


def example_command(fleet: Fleet, locale: str) -> str:
    """`vahr say` of a first command in the fleet's own words and the locale's language:
    its first robot to its first zone but LOADING, as `vahr say` must be given it."""
    from vahr.domain.fleet import SPOKEN_LOCALE, spoken_in
    from vahr.domain.locale import load_language

    zone = next((z for z in fleet.zones if z.id != "LOADING"), fleet.zones[0])
    sentence = load_language(locale).example_command.format(
        robot=spoken_in(fleet.robots[0], locale)[0], zone=spoken_in(zone, locale)[0]
    )
    flag = "" if locale == SPOKEN_LOCALE else f" --locale {locale}"
    return f'vahr say{flag} "{sentence}"'


def _people(path: Path | None) -> People | None:
    """The users file, read and checked before anything starts (one line naming a fault)."""
    if path is None:
        return None
    from vahr.domain.people import load_people
    from vahr.errors import VahrError
    from vahr.protocol import ProtocolError

    try:
        return load_people(path)
    except ProtocolError as err:
        raise VahrError(f"--users {path}: {err}") from err


def _who(system: LocalSystem) -> str:
    """The banner's line on who may do what."""
    people, confirm = system.config.people, system.confirmation
    asks = (
        "fleet-wide commands are confirmed with a yes first"
        if confirm
        else "nothing is confirmed first"
    )
    if people is None:
        return f"anyone may do everything, as a supervisor; {asks} (--users FILE gives roles)"
    count = len(people.users)
    signing_in = sum(person.token_sha256 is not None for person in people.users)
    station = (
        f"{signing_in} may sign in at the station"
        if signing_in
        else "nobody may sign in at the station (give people a token_sha256: vahr users token)"
    )
    return (
        f"{count} {'person' if count == 1 else 'people'} from {system.config.users_file}, "
        f"anyone else a {people.default_role}; {asks}; {station}"
    )


def _banner(
    endpoints: dict[str, str | None], fleet: Fleet, voice: bool, locale: str, who: str
) -> str:
    things = fleet.robot_things
    named = (
        ", ".join(things)
        if len(things) <= BANNER_ROBOTS
        else (f"{things[0]} .. {things[-1]} ({len(things):,} robots)")
    )
    lines = [
        "VAHR is up on this machine.",
        f"  data plane  {endpoints['api']}   (AWS_ENDPOINT_URL_IOT_DATA_PLANE)",
        f"  mqtts       {endpoints['mqtts']}   (CA {endpoints['ca']})",
    ]
    if endpoints["mqtt"]:
        lines.append(
            f"  mqtt        {endpoints['mqtt']}   (plaintext: any program here may use it)"
        )
    lines += [
        f"  station     {endpoints['station'] or '(off)'}   (the operator station page)",
        f"  robots      {named} (sim backend{', room voice' if voice else ''})",
        f"  people      {who}",
        f"  talk to it: {example_command(fleet, locale)}   (Ctrl-C stops everything)",
    ]
    return "\n".join(lines)


class _EventPrinter:
    """Prints robots' events, holding those that come before the endpoints are printed:
    the endpoints are the first line (a contract scripts rely on), and robots that resume
    work while the system starts must not push it down nor be dropped.

    With `--json` every event is a line. Otherwise the lines are for a person: progress is
    chatter, printed only at `--log-level DEBUG`, and one command's same event from several
    robots within `COALESCE_S` is one line naming them ("rover1, rover2 and 998 more
    accepted"), so a fleet command to a swarm of 1,000 is a few lines, not thousands."""

    def __init__(self, as_json: bool, *, progress: bool = False) -> None:
        self._as_json = as_json
        self._progress = progress
        self._lock = threading.Lock()
        self._held: list[Event] | None = []
        # (command id, event, zone) -> the events gathered, and when the first came.
        self._groups: dict[tuple[str | None, str, str | None], tuple[float, list[Event]]] = {}
        self._stopping = threading.Event()
        self._flusher: threading.Thread | None = None
        if not as_json:
            self._flusher = threading.Thread(target=self._flush_loop, daemon=True)
            self._flusher.start()

    def print(self, event: Event) -> None:
        if not self._as_json and event.event == "progress" and not self._progress:
            return
        with self._lock:
            if self._held is not None:
                self._held.append(event)
                return
            if not self._as_json:
                key = (event.command_id, event.event, event.zone)
                _, events = self._groups.setdefault(key, (time.monotonic(), []))
                events.append(event)
                return
        _print_event(event, self._as_json)

    def release(self) -> None:
        with self._lock:
            held, self._held = self._held or [], None
        for event in held:
            self.print(event)

    def stop(self) -> None:
        """Print what is still gathered, and stop."""
        self._stopping.set()
        if self._flusher is not None:
            self._flusher.join(timeout=2 * COALESCE_S)
        self._flush(every=True)

    def _flush_loop(self) -> None:
        while not self._stopping.wait(COALESCE_S / 4):
            self._flush()

    def _flush(self, *, every: bool = False) -> None:
        now = time.monotonic()
        with self._lock:
            due = [
                key
                for key, (first, _) in self._groups.items()
                if every or now - first >= COALESCE_S
            ]
            groups = [self._groups.pop(key)[1] for key in due]
        for events in groups:
            if len(events) == 1:
                _print_event(events[0], as_json=False)
            else:
                _print_group(events)


def _print_group(events: list[Event]) -> None:
    """One line for one command's same event from several robots."""
    first = events[0]
    things = list(dict.fromkeys(event.thing for event in events))
    shown = ", ".join(things[:GROUP_NAMED])
    named = (
        f"{shown} and {len(things) - GROUP_NAMED:,} more" if len(things) > GROUP_NAMED else shown
    )
    details = _details(first)
    command = f" [{first.command_id[:8]}]" if first.command_id else ""
    stamp = first.at.strftime("%H:%M:%S")
    _emit(f"{stamp} {len(things):,} robots {first.event}: {named} {details}{command}".rstrip())


def _print_event(event: Event, as_json: bool) -> None:
    if as_json:
        from vahr.protocol import encode

        _emit(encode(event).decode())
        return
    command = f" [{event.command_id[:8]}]" if event.command_id else ""
    stamp = event.at.strftime("%H:%M:%S")
    _emit(f"{stamp} {event.thing:<10} {event.event:<10} {_details(event)}{command}")


def _details(event: Event) -> str:
    details = [
        f"{name}={value}"
        for name, value in (
            ("zone", event.zone),
            ("action", event.action),
            ("reason", event.reason),
            ("text", event.text),
            ("intent", event.intent),
        )
        if value is not None
    ]
    if event.progress is not None:
        details.append(f"progress={event.progress:.0%}")
    return " ".join(details)
