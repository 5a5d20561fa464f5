"""Robot-agent processes for the local stack: one `robot-agent run` per robot, each with
its own certificate from the local CA, the simulator backend and its own log file; or, for
`vahr up --swarm N`, one `robot-agent swarm` process running N robots of a generated
fleet (`generated_fleet`) on one connection.

A robot runs from the installed package, as it would on a robot: nothing puts a checkout
on its import path, and it starts in this process's working directory.
"""

from __future__ import annotations

import logging
import math
import signal
import subprocess
import sys
import threading
from typing import TYPE_CHECKING, Literal

import msgspec

from vahr.domain import FLEET_GROUP, Fleet, Group, Pose, Robot, load_fleet
from vahr.domain.fleet import Conveyor, Floor, Point, Segment
from vahr.errors import VahrError
from vahr.navigation import load_floor
from vahr.plumbing.lifetime import spawn

if TYPE_CHECKING:
    from pathlib import Path

    from vahr.pki import LocalCA
    from vahr.protocol.broker import ClientCredentials

log = logging.getLogger(__name__)

STOP_TIMEOUT_S = 8.0
# `vahr up --swarm N`: the most robots one swarm runs here. Memory does not bind: the swarm
# process measured 34.5 MB at 100 robots, 47.7 MB at 1,000 and 92 MB at 5,000 (11 to 15 kB
# a robot; bench/swarm_startup.py, docs/large-fleets.md). What binds is Alexa's limit of
# 1,000,000 characters on an interaction model, whose ROBOT slot type names every robot:
# about 4,250 rovers fit today (955,909 characters at 4,000, 172 more a robot), and the
# intents' samples grow as the skill learns phrasings (5,000 fitted before "the robot"
# requests came, 4,514 before the battery and service intents), so the bound keeps some in
# hand; a test checks the model of this many fits.
SWARM_MAX = 4_000
# The swarm's floor: robots parked on a grid of this spacing, clear of the zones.
SWARM_SPACING_M = 2.0
SWARM_ZONE_CLEARANCE_M = 4.0
# On a map: robots added to a fleet, or a swarm's, park this far apart on free ground and
# this far from every zone.
MAP_PARKING_SPACING_M = 0.6
MAP_PARKING_ZONE_CLEARANCE_M = 0.8


def fleet_of(count: int | None, base: Fleet | None = None) -> Fleet:
    """The fleet's first `count` robots or, past its size, more `placebotN` robots."""
    base = base or load_fleet()
    if count is None:
        return base
    if count < 1:
        raise VahrError(f"--robots {count}: at least one robot is needed")
    robots = list(base.robots[:count])
    added = range(len(robots) + 1, count + 1)
    floor = load_floor(base)
    if floor is not None:
        # On a map, added robots park on free ground between the fleet's robots and zones.
        spots = floor.parking(
            len(added),
            spacing=MAP_PARKING_SPACING_M,
            clear_of_zones=MAP_PARKING_ZONE_CLEARANCE_M,
            avoid=[robot.start for robot in robots],
        )
    else:
        # A grid west of the loading zone, 1 m apart, so no robot starts in a zone.
        spots = [Pose(x=-1.0 - (index - 1) // 20, y=float((index - 1) % 20)) for index in added]
    for index, spot in zip(added, spots, strict=True):
        robots.append(
            Robot(
                thing=f"placebot{index}", spoken=[f"placebot {index}", f"robot {index}"], start=spot
            )
        )
    things = [robot.thing for robot in robots]
    # Each group keeps its names in every language; only its members change.
    groups = [
        msgspec.structs.replace(group, robots=[t for t in group.robots if t in things])
        for group in base.groups
    ]
    if not any(group.id == FLEET_GROUP for group in groups):
        groups.append(Group(id=FLEET_GROUP, spoken=["all robots"], robots=things))
    groups = [
        msgspec.structs.replace(g, robots=things) if g.id == FLEET_GROUP else g
        for g in groups
        if g.robots or g.id == FLEET_GROUP
    ]
    # The robots added start west of the floor the file draws: it grows to hold them.
    grown = base.floor
    if grown is not None and grown.map is None:
        grown = grown.covering([robot.start for robot in robots])
    return Fleet(
        robots=robots,
        zones=base.zones,
        groups=groups,
        experiment_thing=base.experiment_thing,
        floor=grown,
    ).validate()


def generated_fleet(count: int, base: Fleet | None = None) -> Fleet:
    """`count` robots `rover1`.. ("rover 17") on a floor sized for them: the zones of `base`
    (default fleet.yaml) keep their names and arms, the loading zone mid-way along the west
    wall and the others spread along the east wall; the robots are parked on a square grid
    between them, `SWARM_SPACING_M` apart, none in a zone."""
    if not 1 <= count <= SWARM_MAX:
        raise VahrError(f"--swarm {count}: give 1 to {SWARM_MAX:,} robots")
    base = base or load_fleet()
    if base.floor is not None and base.floor.map is not None:
        return _generated_on_map(count, base)
    columns = math.ceil(math.sqrt(count))
    rows = math.ceil(count / columns)
    grid_width, grid_height = (columns - 1) * SWARM_SPACING_M, (rows - 1) * SWARM_SPACING_M
    left = SWARM_ZONE_CLEARANCE_M + 1.5
    width = left + grid_width + SWARM_ZONE_CLEARANCE_M + 1.5
    height = max(grid_height + 4.0, 8.0)
    bottom = (height - grid_height) / 2
    robots = [
        Robot(
            thing=f"rover{index}",
            spoken=[f"rover {index}"],
            start=Pose(
                left + ((index - 1) % columns) * SWARM_SPACING_M,
                bottom + ((index - 1) // columns) * SWARM_SPACING_M,
            ),
        )
        for index in range(1, count + 1)
    ]
    loading = [zone for zone in base.zones if zone.arm == "loader"]
    delivery = [zone for zone in base.zones if zone.arm != "loader"]
    zones = [
        msgspec.structs.replace(zone, pose=Pose(1.5, height / 2, math.pi)) for zone in loading
    ] + [
        msgspec.structs.replace(
            zone, pose=Pose(width - 1.5, height * (len(delivery) - i - 0.5) / len(delivery), 0.0)
        )
        for i, zone in enumerate(delivery)
    ]
    corners = [Point(0.0, 0.0), Point(width, 0.0), Point(width, height), Point(0.0, height)]
    floor = Floor(
        width=width,
        height=height,
        walls=[Segment(corners[i], corners[(i + 1) % 4]) for i in range(4)],
        conveyor=Conveyor(Point(0.0, height / 2), Point(0.9, height / 2)) if loading else None,
    )
    everyone = next((g for g in base.groups if g.id == FLEET_GROUP), None)
    spoken = everyone.spoken if everyone is not None else ["all robots"]
    return Fleet(
        robots=robots,
        zones=zones,
        groups=[Group(id=FLEET_GROUP, spoken=spoken, robots=[r.thing for r in robots])],
        experiment_thing=base.experiment_thing,
        floor=floor,
    ).validate()


def _generated_on_map(count: int, base: Fleet) -> Fleet:
    """`count` rovers on `base`'s map, parked on its free ground; the zones are `base`'s."""
    floor = load_floor(base)
    assert floor is not None
    spots = floor.parking(
        count, spacing=MAP_PARKING_SPACING_M, clear_of_zones=MAP_PARKING_ZONE_CLEARANCE_M
    )
    robots = [
        Robot(thing=f"rover{index}", spoken=[f"rover {index}"], start=spot)
        for index, spot in enumerate(spots, start=1)
    ]
    everyone = next((g for g in base.groups if g.id == FLEET_GROUP), None)
    spoken = everyone.spoken if everyone is not None else ["all robots"]
    return Fleet(
        robots=robots,
        zones=base.zones,
        groups=[Group(id=FLEET_GROUP, spoken=spoken, robots=[r.thing for r in robots])],
        experiment_thing=base.experiment_thing,
        floor=base.floor,
    ).validate()


def write_fleet(fleet: Fleet, path: Path) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_bytes(msgspec.yaml.encode(fleet))
    return path


# Every robot here runs on this machine's clock, so a sequential delivery needs no
# tolerance for clocks that disagree (see robot-agent's `peer_clock_skew_s`).
SAME_CLOCK = "executor:\n  peer_clock_skew_s: 0\n"
# Messages cost nothing here, so robots report their progress every simulated second, as
# often as the station wants for smooth drawing; on AWS the agent's defaults report far
# less often (docs/robot-agent.md, "Progress reports").
LOCAL_PROGRESS = "  progress_interval_s: 1\n  progress_step: 0\n"
# `vahr fault` may inject faults into the robots of `vahr up` (robot_agent.dev_faults).
ACCEPT_FAULTS = "sim:\n  accept_faults: true\n"
LOCAL_AGENT_CONFIG = SAME_CLOCK + LOCAL_PROGRESS + ACCEPT_FAULTS


def swarm_agent_config(sim_speed_factor: float) -> str:
    """The agent settings of a swarm: as `LOCAL_AGENT_CONFIG`, but a robot reports its
    progress once a wall-clock second, not once a simulated one. A thousand robots at speed
    factor 5 reporting every simulated second sent the station 5,000 progress events a
    second (27,479 in the 15 s of one fleet command), more than its map can use: it draws a
    robot's motion between reports (static/motion.js)."""
    interval = max(1.0, sim_speed_factor)
    progress = f"  progress_interval_s: {interval:g}\n  progress_step: 0\n"
    return SAME_CLOCK + progress + ACCEPT_FAULTS


# Which progress rate the robots of `vahr up` use: the local one, or the agent's own
# defaults (the rate a deployment on AWS gets; for measuring what it would bill).
ProgressRate = Literal["local", "aws"]


class RobotProcesses:
    """Start, watch and stop one `robot-agent run` process per robot."""

    def __init__(
        self,
        *,
        fleet_file: Path,
        things: list[str],
        ca: LocalCA,
        mqtts_port: int,
        state_dir: Path,
        sim_speed_factor: float = 1.0,
        voice: str | None = None,
        log_level: str = "INFO",
        progress: ProgressRate = "local",
    ) -> None:
        self.fleet_file = fleet_file
        self.things = things
        self.ca = ca
        self.mqtts_port = mqtts_port
        self.state_dir = state_dir
        self.sim_speed_factor = sim_speed_factor
        self.voice = voice
        self.log_level = log_level
        self.progress = progress
        self.processes: dict[str, subprocess.Popen[bytes]] = {}
        self._lock = threading.Lock()

    def log_file(self, thing: str) -> Path:
        return self.state_dir / thing / "agent.log"

    def command(self, thing: str) -> list[str]:
        credentials = self.ca.issue_client(thing, self.state_dir / thing / "certs")
        config = self.state_dir / thing / "agent.yaml"
        config.write_text(
            LOCAL_AGENT_CONFIG if self.progress == "local" else SAME_CLOCK + ACCEPT_FAULTS
        )
        command = [
            sys.executable, "-m", "robot_agent.cli", "run",
            "--config", str(config),
            "--thing", thing,
            "--endpoint", "127.0.0.1", "--port", str(self.mqtts_port),
            "--cert", str(credentials.cert_file),
            "--key", str(credentials.key_file),
            "--ca", str(credentials.ca_file),
            "--backend", "sim",
            "--sim-speed-factor", f"{self.sim_speed_factor:g}",
            "--fleet", str(self.fleet_file),
            "--state-dir", str(self.state_dir / thing / "state"),
            "--log-level", self.log_level,
        ]  # fmt: skip
        if self.voice:
            command += ["--voice", self.voice]
        return command

    def start(self) -> RobotProcesses:
        for thing in self.things:
            self.restart(thing)
        return self

    def restart(self, thing: str) -> None:
        """Start `thing`'s process (again, after it ended); its log file is appended to."""
        log_path = self.log_file(thing)
        log_path.parent.mkdir(parents=True, exist_ok=True)
        with log_path.open("ab") as log_stream:
            # Tied to this process's life: a robot never outlives the `vahr up` that
            # started it, even one killed with SIGKILL (see `lifetime`).
            process = spawn(
                self.command(thing),
                started_for=self.state_dir,
                stdin=subprocess.DEVNULL,
                stdout=log_stream,
                stderr=subprocess.STDOUT,
                # Their own process group: Ctrl-C reaches `vahr up`, which stops them
                # in order, rather than every process at once.
                start_new_session=True,
            )
        with self._lock:
            self.processes[thing] = process

    def exited(self) -> dict[str, int]:
        """Robots whose process has ended, with the exit code."""
        with self._lock:
            return {t: p.returncode for t, p in self.processes.items() if p.poll() is not None}

    def last_log_line(self, thing: str) -> str:
        path = self.log_file(thing)
        lines = path.read_text(errors="replace").strip().splitlines() if path.exists() else []
        return lines[-1] if lines else "no output"

    def stop(self) -> None:
        """SIGTERM to every robot, then wait; SIGKILL whatever outlives the timeout."""
        with self._lock:
            processes, self.processes = self.processes, {}
        for process in processes.values():
            if process.poll() is None:
                process.send_signal(signal.SIGTERM)
        for thing, process in processes.items():
            try:
                process.wait(timeout=STOP_TIMEOUT_S)
            except subprocess.TimeoutExpired:
                log.warning("%s did not stop within %s s; killing it", thing, STOP_TIMEOUT_S)
                process.kill()
                process.wait(timeout=STOP_TIMEOUT_S)


class SwarmProcess:
    """One `robot-agent swarm` process running every robot of `fleet_file`, watched and
    stopped like `RobotProcesses` (its one process is named `SWARM`)."""

    SWARM = "swarm"

    def __init__(
        self,
        *,
        fleet_file: Path,
        count: int,
        credentials: ClientCredentials,
        mqtts_port: int,
        state_dir: Path,
        sim_speed_factor: float = 1.0,
        log_level: str = "INFO",
    ) -> None:
        self.fleet_file = fleet_file
        self.count = count
        self.credentials = credentials
        self.mqtts_port = mqtts_port
        self.state_dir = state_dir
        self.sim_speed_factor = sim_speed_factor
        self.log_level = log_level
        self.process: subprocess.Popen[bytes] | None = None

    def log_file(self, _name: str = SWARM) -> Path:
        return self.state_dir / "swarm.log"

    def command(self) -> list[str]:
        config = self.state_dir / "agent.yaml"
        config.write_text(swarm_agent_config(self.sim_speed_factor))
        credentials = self.credentials
        return [
            sys.executable, "-m", "robot_agent.cli", "swarm",
            "--fleet", str(self.fleet_file),
            "--count", str(self.count),
            "--config", str(config),
            # One connection speaks for every robot: the local services' identity.
            "--endpoint", "127.0.0.1", "--port", str(self.mqtts_port),
            "--cert", str(credentials.cert_file),
            "--key", str(credentials.key_file),
            "--ca", str(credentials.ca_file),
            "--client-id", "vahr-swarm",
            "--sim-speed-factor", f"{self.sim_speed_factor:g}",
            "--state-dir", str(self.state_dir / "state"),
            "--log-level", self.log_level,
        ]  # fmt: skip

    def start(self) -> SwarmProcess:
        self.restart(self.SWARM)
        return self

    def restart(self, _name: str = SWARM) -> None:
        """Start the swarm (again, after it ended); its log file is appended to."""
        self.state_dir.mkdir(parents=True, exist_ok=True)
        with self.log_file().open("ab") as log_stream:
            self.process = spawn(
                self.command(),
                started_for=self.state_dir,
                stdin=subprocess.DEVNULL,
                stdout=log_stream,
                stderr=subprocess.STDOUT,
                start_new_session=True,
            )

    def exited(self) -> dict[str, int]:
        process = self.process
        if process is None or process.poll() is None:
            return {}
        return {self.SWARM: process.returncode}

    def last_log_line(self, _name: str = SWARM) -> str:
        path = self.log_file()
        lines = path.read_text(errors="replace").strip().splitlines() if path.exists() else []
        return lines[-1] if lines else "no output"

    def stop(self) -> None:
        """SIGTERM, then wait (every robot reports offline); SIGKILL if it outlives that."""
        process, self.process = self.process, None
        if process is None:
            return
        if process.poll() is None:
            process.send_signal(signal.SIGTERM)
        try:
            process.wait(timeout=STOP_TIMEOUT_S * 2)
        except subprocess.TimeoutExpired:
            log.warning("the robot swarm did not stop within %s s; killing it", STOP_TIMEOUT_S * 2)
            process.kill()
            process.wait(timeout=STOP_TIMEOUT_S)
