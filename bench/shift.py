"""A shift, measured: eight hours of deliveries by ten robots whose batteries drain, once
with the dispatcher that respects the charge and once with one that ignores it, seeded.

The floor is the bundled one (the paper's warehouse: the loading zone on the west wall, A
to D on the east wall) with two charging zones added, and ten robots of one type whose
battery drains by the metre and by the hour and charges at a charger (`battery:` below).
Each robot starts the shift with a charge drawn from `--start-charge` (a shift does not
start with every robot full). `--deliveries` orders arrive at random times over the shift,
each to a random zone of A to D.

The shift runs in simulated time (one step a simulated second: an infinite speed factor),
on the parts that decide: the dispatch core (`vahr.dispatch.Dispatcher`, the energy rule,
the chargers held like tasks) over the local host's SQLite task store, and each robot's
battery as the simulator drains and charges it (`robot_agent.backends.sim_battery`). The
robots themselves are a kinematic stand-in of the simulator (straight drives at its
0.5 m/s, three seconds at each arm): what is measured is the dispatch and the batteries,
not MQTT. A robot whose battery runs out stops where it is, its task failed.

Figures per dispatcher: deliveries done, done per hour, the lowest charge any robot
reached, tasks started that could not be finished (their robot ran out of charge), and
what became of every other task (still in line at the end, and why). Targets, for the
dispatcher that respects the charge: no robot below its reserve, no task started that could
not be finished, every task done or said why not.
"""

from __future__ import annotations

import argparse
import json
import random
import sys
import tempfile
import textwrap
import time
from collections import Counter
from dataclasses import dataclass, field
from datetime import UTC, datetime, timedelta
from pathlib import Path

import msgspec
from _results import write_section

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from robot_agent.backends.sim_battery import SimBattery  # noqa: E402
from vahr.dispatch import Dispatcher, Order, RobotState  # noqa: E402
from vahr.domain import Fleet, Pose, Robot, Zone, load_fleet  # noqa: E402
from vahr.domain.battery import BatteryPlan, BatteryType  # noqa: E402
from vahr.local.task_store import SqliteTaskStore  # noqa: E402
from vahr.protocol import Battery  # noqa: E402

SHIFT_H = 8.0
SPEED_MPS = 0.5
ARM_S = 3.0
ROBOTS = 10
DELIVERIES = 300
# One type of robot, as a small indoor delivery robot drains on this small floor.
RATES = BatteryType(
    drain_per_m=0.05, idle_drain_per_h=2.0, working_drain_per_h=6.0, charge_per_h=40.0
)
PLAN = BatteryPlan(
    charge_below=20.0, reserve=10.0, charged=90.0, types={"standard": RATES}, arm_time_s=6.0
)


COLUMNS = (
    "dispatcher",
    "deliveries done",
    "done per hour",
    "lowest charge %",
    "started, not finished",
    "robots out of charge",
    "charges",
    "in line at end",
    "under way at end",
    "wall s",
)
HEADER = "| " + " | ".join(COLUMNS) + " |"
RULE = "| --- |" + " ---: |" * (len(COLUMNS) - 1)


def shift_fleet(robots: int) -> Fleet:
    """The bundled floor with two chargers and `robots` robots parked along its middle."""
    bundled = load_fleet()
    chargers = [
        Zone(id="DOCK1", spoken=["dock one"], pose=Pose(3.0, 1.0), charger=True),
        Zone(id="DOCK2", spoken=["dock two"], pose=Pose(3.0, 7.0), charger=True),
    ]
    parked = [
        Robot(
            thing=f"rover{n}",
            spoken=[f"rover number {n}"],
            start=Pose(3.0 + 0.5 * (n % 10), 2.0 + 0.4 * (n // 10) + (n % 2) * 3.5),
        )
        for n in range(1, robots + 1)
    ]
    fleet = msgspec.structs.replace(
        bundled, robots=parked, zones=[*bundled.zones, *chargers], groups=[], battery=PLAN
    )
    return fleet.validate()


SHIFT_START = datetime(2026, 11, 30, 6, 0, tzinfo=UTC)


@dataclass
class ShiftClock:
    """The simulator's clock, moved by the shift one step at a time."""

    seconds: float = 0.0

    def monotonic(self) -> float:
        return self.seconds

    def now(self) -> datetime:
        return SHIFT_START + timedelta(seconds=self.seconds)

    async def sleep(self, seconds: float) -> None:
        raise NotImplementedError("the shift steps its clock itself")


@dataclass
class Bot:
    """One robot: where it is, the legs of the command it runs, and its battery."""

    thing: str
    pose: Pose
    battery: SimBattery
    legs: list[tuple[str, Zone | float]] = field(default_factory=list)
    command: str | None = None
    result: str | None = None
    zone: str | None = None
    status: str = "idle"
    dead: bool = False

    def state(self) -> RobotState:
        reading = self.battery.reading()
        return RobotState(
            thing=self.thing,
            status=self.status,
            zone=self.zone,
            pose=self.pose,
            last_command_id=self.command,
            last_result=self.result,
            battery=Battery(percent=reading.percent, charging=reading.charging),
        )


class Shift:
    """One shift with one dispatcher: the robots, their commands and the tally."""

    def __init__(self, fleet: Fleet, starts: list[float], *, respect: bool, store: Path) -> None:
        self.fleet = fleet
        self.clock = ShiftClock()
        self.changed: set[str] = set()
        self.died: set[str] = set()
        self.bots: dict[str, Bot] = {}
        self.bots = {
            robot.thing: Bot(robot.thing, robot.start, self._battery(robot, percent))
            for robot, percent in zip(fleet.robots, starts, strict=True)
        }
        self.store = SqliteTaskStore(store)
        self.dispatcher = Dispatcher(
            fleet=fleet,
            store=self.store,
            candidates=self,
            publish=self._publish,
            clock=self.clock.now,
            respect_battery=respect,
        )
        self.lowest = min(starts)

    def _battery(self, robot: Robot, percent: float) -> SimBattery:
        thing, start = robot.thing, robot.start

        def pose() -> Pose:
            bot = self.bots.get(thing)
            return bot.pose if bot is not None else start

        def changed(reading: Battery) -> None:
            self.changed.add(thing)

        battery = SimBattery(
            clock=self.clock,
            pose=pose,
            rates=self.fleet.battery_rates(thing),
            chargers=self.fleet.chargers,
            percent=percent,
        )
        battery.watch(changed)
        return battery

    # -- the Candidates port ----------------------------------------------------------

    def available(self, *, zone: str | None = None) -> list[RobotState]:
        states = [bot.state() for bot in self.bots.values()]
        return [s for s in states if s.available and (zone is None or s.zone == zone)]

    def state(self, thing: str) -> RobotState | None:
        bot = self.bots.get(thing)
        return bot.state() if bot is not None else None

    # -- the robots ---------------------------------------------------------------------

    def _publish(self, thing: str, command: object) -> None:
        bot = self.bots[thing]
        action = getattr(command, "action", "")
        command_id = str(getattr(command, "id", ""))
        if bot.dead:
            bot.command, bot.result = command_id, "failed"
            self.changed.add(thing)
            return
        bot.command, bot.result = command_id, "accepted"
        if action == "stop":
            bot.legs, bot.status, bot.result = [], "stopped", "done"
        else:
            zone = self.fleet.zone(getattr(command.params, "zone", ""))  # type: ignore[attr-defined]
            legs: list[tuple[str, Zone | float]] = []
            if action == "deliver":
                legs += [("drive", self.fleet.zone("LOADING")), ("arm", ARM_S)]
                legs += [("drive", zone), ("arm", ARM_S)]
            else:
                legs.append(("drive", zone))
            bot.legs, bot.status, bot.zone = legs, "navigating", zone.id
            bot.battery.set_working(True)
        self.changed.add(thing)

    def step(self, dt: float) -> None:
        self.clock.seconds += dt
        for bot in self.bots.values():
            if bot.dead or not bot.legs:
                bot.battery.settle()
                continue
            kind, what = bot.legs[0]
            if kind == "arm":
                left = float(what) - dt  # type: ignore[arg-type]
                bot.status = "loading" if len(bot.legs) > 1 else "unloading"
                bot.legs[0] = ("arm", left)
                if left <= 0:
                    bot.legs.pop(0)
            else:
                goal = what.pose  # type: ignore[union-attr]
                away = bot.pose.distance_to(goal)
                metres = min(away, SPEED_MPS * dt, bot.battery.range_m)
                if away > 0:
                    f = metres / away
                    bot.pose = Pose(
                        bot.pose.x + (goal.x - bot.pose.x) * f,
                        bot.pose.y + (goal.y - bot.pose.y) * f,
                    )
                bot.battery.drove(metres)
                if bot.pose.distance_to(goal) < 1e-6:
                    bot.legs.pop(0)
            bot.battery.settle()
            if bot.battery.empty and bot.legs:
                # Out of charge: it stops where it is and its command fails.
                bot.legs, bot.dead, bot.status, bot.result = [], True, "error", "failed"
                self.died.add(bot.thing)
                self.changed.add(bot.thing)
            elif not bot.legs:
                bot.battery.set_working(False)
                bot.status, bot.result = "idle", "done"
                self.changed.add(bot.thing)
            self.lowest = min(self.lowest, bot.battery.level)

    def report(self) -> None:
        """Every robot that changed tells the dispatcher, as its shadow update would."""
        while self.changed:
            thing = self.changed.pop()
            self.dispatcher.observe(self.bots[thing].state())


def run(
    seed: int, *, respect: bool, robots: int, deliveries: int, start: tuple[float, float]
) -> dict[str, object]:
    rng = random.Random(seed)
    fleet = shift_fleet(robots)
    starts = [rng.uniform(*start) for _ in range(robots)]
    arrivals = sorted(rng.uniform(0, SHIFT_H * 3600 * 0.95) for _ in range(deliveries))
    zones = [rng.choice(["A", "B", "C", "D"]) for _ in range(deliveries)]
    with tempfile.TemporaryDirectory() as scratch:
        shift = Shift(fleet, starts, respect=respect, store=Path(scratch) / "tasks.sqlite3")
        began = time.perf_counter()
        due = 0
        for _ in range(int(SHIFT_H * 3600)):
            while due < deliveries and arrivals[due] <= shift.clock.seconds:
                shift.dispatcher.submit(Order(kind="deliver", zone=zones[due]))
                due += 1
            shift.step(1.0)
            shift.report()
        wall_s = time.perf_counter() - began
        tasks = shift.store.active() + shift.store.pending()
        every = [
            task for status in ("done", "cancelled") for task in _with_status(shift.store, status)
        ] + tasks
        delivered = [t for t in every if t.kind == "deliver"]
        outcomes = Counter(t.outcome or t.status for t in delivered)
        charges = Counter(t.outcome or t.status for t in every if t.kind == "charge")
        shift.store.close()
    done = outcomes.get("done", 0)
    return {
        "dispatcher": "respects the charge" if respect else "ignores the battery",
        "seed": seed,
        "robots": robots,
        "deliveries": deliveries,
        "done": done,
        "per_hour": round(done / SHIFT_H, 1),
        "lowest_charge": round(shift.lowest, 1),
        "started_unfinished": outcomes.get("failed", 0),
        "in_line_at_end": outcomes.get("queued", 0),
        "under_way_at_end": outcomes.get("assigned", 0),
        "robots_out_of_charge": len(shift.died),
        "charges": sum(charges.values()),
        "outcomes": dict(outcomes),
        "wall_s": round(wall_s, 1),
    }


def _reflowed(body: str) -> str:
    """Each paragraph of `body` wrapped at 92 columns; tables as they are."""
    paragraphs = body.strip().split("\n\n")
    return "\n\n".join(
        part if part.startswith("|") else textwrap.fill(" ".join(part.split()), 92)
        for part in paragraphs
    )


def _with_status(store: SqliteTaskStore, status: str) -> list:  # type: ignore[type-arg]
    return store._with_status(status)  # noqa: SLF001 - the bench reads every task's end


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seed", type=int, default=46)
    parser.add_argument("--robots", type=int, default=ROBOTS)
    parser.add_argument("--deliveries", type=int, default=DELIVERIES)
    parser.add_argument("--start-charge", type=float, nargs=2, default=(15.0, 100.0))
    parser.add_argument("--no-write", action="store_true", help="print, do not write the docs")
    args = parser.parse_args()
    start = tuple(args.start_charge)
    results = [
        run(args.seed, respect=respect, robots=args.robots, deliveries=args.deliveries, start=start)  # type: ignore[arg-type]
        for respect in (True, False)
    ]
    rows = [
        f"| {r['dispatcher']} | {r['done']} | {r['per_hour']} | {r['lowest_charge']} | "
        f"{r['started_unfinished']} | {r['robots_out_of_charge']} | {r['charges']} | "
        f"{r['in_line_at_end']} | {r['under_way_at_end']} | {r['wall_s']} |"
        for r in results
    ]
    respecting = results[0]
    met = (
        float(respecting["lowest_charge"]) >= PLAN.reserve  # type: ignore[arg-type]
        and respecting["started_unfinished"] == 0
    )
    body = f"""
One seeded shift (seed {args.seed}): {SHIFT_H:g} hours, {args.robots} robots, {args.deliveries}
deliveries arriving at random times to zones A to D of the bundled floor, with two chargers
added; each robot starts with a charge drawn from {start[0]:g} to {start[1]:g} %. Battery:
{RATES.drain_per_m:g} % a metre, {RATES.idle_drain_per_h:g} % an hour idle,
{RATES.working_drain_per_h:g} % an hour working, {RATES.charge_per_h:g} % an hour at a
charger; charge below {PLAN.charge_below:g} %, reserve {PLAN.reserve:g} %, back in the pool at
{PLAN.charged:g} %. Simulated time on the dispatch core and the simulator's battery model,
the robots a kinematic stand-in (0.5 m/s, 3 s at each arm); both dispatchers in the same run.

{HEADER}
{RULE}
{chr(10).join(rows)}

The lowest charge counts each robot's start. Targets (the dispatcher that respects the
charge): no robot below its reserve, no task
started that could not be finished: {"met" if met else "missed"}. Every delivery not done
is said: still in line at the end of the shift (no robot had the charge for it yet, or
every robot was busy) or under way when it ended.
"""
    body = _reflowed(body)
    print(json.dumps(results))
    if not args.no_write:
        write_section("shift", "A shift, measured: batteries, charging and dispatch", body)
    else:
        print(body)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
