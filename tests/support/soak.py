"""The soak: the whole local system under steady load and random faults, then the books.

`run_soak(config)` starts `vahr up` (broker, shadow service, data plane, the Alexa
simulator with the skill, and two robot-agent processes) and a swarm of simulated robots
on its broker, then for `duration_s`:

- the skill path: utterances through `POST /vahr/say` (what `vahr say` sends), whose real
  ASK request envelopes run the skill handler; every answer is timed against Alexa's 8 s;
- the console path: commands published on the robots' topics with `source: console`,
  as the operator console does, through the relay below; one in ten written instead as
  the robot's desired state through the data plane (`UpdateThingShadow`);
- a fault injector, one fault at a time in a seeded order: mosquitto killed (SIGKILL; `vahr
  up` restarts it), a robot-agent killed (SIGKILL; `vahr up` restarts it), the process
  serving the shadows paused (SIGSTOP, then SIGCONT), and every connection through the
  relay cut (the swarm's link and the console's) as a Wi-Fi drop cuts them.

Then it waits for every robot to finish, and reports from the robots' own records (the
swarm's events as published, the agents' logs) and the shadows: commands executed once,
reported failed or cancelled with a reason, lost, run twice; shadows that did not converge;
the largest RSS of each process; the skill's slowest answer; the longest recovery after a
broker restart (broker back to a ping answered by both agents and a swarm robot). The
books of the run are left in `{work_dir}/ledger.json` beside the state directory.
"""

from __future__ import annotations

import contextlib
import dataclasses
import itertools
import json
import os
import random
import re
import signal
import statistics
import threading
import time
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from robot_agent.config import ExecutorSettings
from tests.support.fault_injection_steps import TcpProxy, alive, kill_hard, processes_of, wait_until
from tests.support.soak_ledger import Ledger, Record, Sent, Verdict, read_agent_log
from tests.support.swarm_runner import SwarmThread
from tests.support.vahr_up import start_up, stop_up
from vahr.errors import VahrError
from vahr.pki import LocalCA
from vahr.plumbing.client import call, say
from vahr.plumbing.mqtt import MqttClient, MqttEndpoint, PublishUnconfirmed
from vahr.plumbing.ports import free_port
from vahr.protocol import encode, new_command, topics
from vahr.twin import identities

if TYPE_CHECKING:
    from tests.support.vahr_up import Up

SKILL_DEADLINE_S = 8.0  # Alexa's limit for a skill's answer
# Stated before any run, from the sizes at start (vahr up about 90 MB, mosquitto 10 MB, a
# robot-agent 35 MB): a process past its bound is growing, not just busy.
MEMORY_BOUNDS_MB = {"vahr up": 384, "mosquitto": 64, "robot-agent": 128, "swarm": 512}
FAULTS = ("broker restart", "robot-agent kill", "shadow pause", "connection drop")
AGENTS = ("placebot1", "placebot2")
SPOKEN = {"placebot1": "placebot one", "placebot2": "placebot two"}
ZONES = ("A", "B", "C", "D", "LOADING")
RECOVERY_TIMEOUT_S = 60.0


@dataclass(frozen=True, kw_only=True)
class SoakConfig:
    duration_s: float
    work_dir: Path
    seed: int = 16
    swarm_size: int = 100
    console_interval_s: float = 0.5
    skill_interval_s: float = 2.0
    fault_interval_s: float = 20.0
    sim_speed_factor: float = 20.0
    settle_timeout_s: float = 120.0
    sample_interval_s: float = 2.0


@dataclass
class Fault:
    kind: str
    at_s: float
    detail: str
    survived: bool
    recovery_s: float | None = None  # broker restarts: broker back to every robot answering


@dataclass
class SkillTurn:
    utterance: str
    latency_s: float
    speech: str
    error: str | None = None


@dataclass
class SoakReport:
    config: SoakConfig
    verdict: Verdict
    faults: list[Fault]
    turns: list[SkillTurn]
    rss_mb: dict[str, tuple[float, float]]  # role -> (first sample, largest)
    unconverged: list[str]
    shadows_checked: int
    crashes: list[str]
    elapsed_s: float
    swarm_reconnects: int = 0

    @property
    def slow_or_invalid_turns(self) -> list[SkillTurn]:
        return [
            t
            for t in self.turns
            if t.error or t.latency_s > SKILL_DEADLINE_S or not t.speech.strip()
        ]

    @property
    def memory_over_bound(self) -> list[str]:
        return [
            f"{role} {largest:.0f} MB > {MEMORY_BOUNDS_MB[role]} MB"
            for role, (_, largest) in self.rss_mb.items()
            if largest > MEMORY_BOUNDS_MB[role]
        ]

    @property
    def longest_recovery_s(self) -> float | None:
        recoveries = [f.recovery_s for f in self.faults if f.recovery_s is not None]
        return max(recoveries) if recoveries else None


class Soak:
    """One run; see the module docstring. `run()` returns the report and stops everything."""

    def __init__(self, config: SoakConfig) -> None:
        self.config = config
        self.state = config.work_dir / "state"
        self.ledger = Ledger()
        self.faults: list[Fault] = []
        self.turns: list[SkillTurn] = []
        self.rss: dict[str, list[float]] = {}
        self.crashes: list[str] = []
        self.kills: dict[str, int] = dict.fromkeys(AGENTS, 0)
        self._stop_load = threading.Event()
        self._started = 0.0
        self.up: Up | None = None
        self.relay: TcpProxy | None = None  # the swarm's connection
        self.console_relay: TcpProxy | None = None
        self.swarm: SwarmThread | None = None
        self.console: MqttClient | None = None
        self.mqtt_port = 0

    # -- the run ----------------------------------------------------------------------

    def run(self) -> SoakReport:
        cfg = self.config
        self.state.mkdir(parents=True, exist_ok=True)
        try:
            self._start()
            self._started = time.monotonic()
            workers = [
                threading.Thread(target=self._console_load, name="soak-console", daemon=True),
                threading.Thread(target=self._skill_load, name="soak-skill", daemon=True),
                threading.Thread(target=self._sample_memory, name="soak-rss", daemon=True),
            ]
            for worker in workers:
                worker.start()
            self._inject_faults(deadline=self._started + cfg.duration_s)
            self._stop_load.set()
            for worker in workers:
                worker.join(30)
            elapsed = time.monotonic() - self._started
            records = self._settle()
            unconverged, checked = self._check_shadows()
            verdict = self.ledger.verdict(records)
            self._write_books(records)
            self._check_alive()
            return SoakReport(
                config=cfg,
                verdict=verdict,
                faults=self.faults,
                turns=self.turns,
                rss_mb={r: (s[0], max(s)) for r, s in self.rss.items() if s},
                unconverged=unconverged,
                shadows_checked=checked,
                crashes=self.crashes,
                elapsed_s=elapsed,
                swarm_reconnects=self.relay.accepted - 1 if self.relay else 0,
            )
        finally:
            self._stop_load.set()
            self._stop()

    def _start(self) -> None:
        cfg = self.config
        self.mqtt_port = free_port()
        self.up = start_up(
            self.state,
            "--robots", str(len(AGENTS)),
            # The console publishes on the plaintext development listener.
            "--dev-plaintext", "--mqtt-port", str(self.mqtt_port),
            "--station-port", "0",
            "--sim-speed-factor", f"{cfg.sim_speed_factor:g}",
            # Robot-agents log each event at INFO only when `vahr up` runs at DEBUG: their
            # logs are the robots' own records the books are kept from.
            "--log-level", "DEBUG",
        )  # fmt: skip
        threading.Thread(target=self._drain_up, name="soak-up-lines", daemon=True).start()
        mqtts_port = int(self.up.endpoints["mqtts"].rsplit(":", 1)[1])
        self.relay = TcpProxy(mqtts_port)
        self.console_relay = TcpProxy(self.mqtt_port)
        self.swarm = SwarmThread(
            # The mTLS listener with the services' identity: mosquitto 2.0.11 restores an
            # anonymous session after a crash without the identity its ACL needs, and then
            # drops what is queued for it (docs/reliability.md); a robot always has one.
            broker=f"mqtts://127.0.0.1:{self.relay.port}",
            tls=LocalCA.load_or_create(self.state).service_credentials(identities.SWARM),
            count=cfg.swarm_size,
            speed_factor=cfg.sim_speed_factor,
            # Generous stuck detection: a starved simulator on a shared machine is not stuck.
            settings=ExecutorSettings(stuck_after_s=600),
            client_id="vahr-soak-swarm",
            # A persistent session, as every real robot has: commands sent while the link
            # is cut are queued by the broker.
            session_expiry_s=3600,
            on_event=self.ledger.swarm_event,
        ).start(timeout_s=60)
        self.console = MqttClient(MqttEndpoint(port=self.console_relay.port)).connect()

    def _drain_up(self) -> None:
        # `vahr up --json` prints every robot's event; nobody reads them here.
        up = self.up
        while up is not None and up.process.poll() is None:
            with contextlib.suppress(Exception):
                up.lines.get(timeout=1)

    def _stop(self) -> None:
        if self.console is not None:
            self.console.stop()
        if self.swarm is not None:
            self.swarm.stop()
        for relay in (self.relay, self.console_relay):
            if relay is not None:
                relay.close()
        if self.up is not None:
            os.kill(self.up.process.pid, signal.SIGCONT)  # in case a pause was under way
            stop_up(self.up.process)
        for leftover in processes_of(self.state):
            kill_hard(leftover.pid)

    # -- load -------------------------------------------------------------------------

    def _wait_tick(self, interval_s: float, tick: int) -> bool:
        """Steady rate: wait for tick `tick` of `interval_s`; False once the load stops."""
        due = self._started + tick * interval_s
        return not self._stop_load.wait(max(0.0, due - time.monotonic()))

    def _console_load(self) -> None:
        rng = random.Random(f"{self.config.seed}-console")
        assert self.swarm is not None and self.console is not None and self.up is not None
        api = self.up.endpoints["api"]
        swarm_things = self.swarm.things
        for tick in itertools.count():
            if not self._wait_tick(self.config.console_interval_s, tick):
                return
            thing = rng.choice(AGENTS) if rng.random() < 0.2 else rng.choice(swarm_things)
            action = rng.choices(["navigate", "deliver", "stop", "ping"], [5, 2, 1, 2])[0]
            params: dict[str, object] | None = (
                {"zone": rng.choice(ZONES[:4])} if action in ("navigate", "deliver") else None
            )
            command = new_command(action, params, source="console")
            # One in ten is written as the robot's desired state instead (docs/protocol.md: for a
            # robot that may be offline); the robot applies it from the shadow's delta.
            path = "shadow" if rng.random() < 0.1 else "console"
            error, unconfirmed = None, False
            try:
                if path == "shadow":
                    desired = {"state": {"desired": {"command": json.loads(encode(command))}}}
                    call(api, "POST", f"/things/{thing}/shadow", desired)
                else:
                    self.console.publish(topics.robot_cmd(thing), encode(command))
            except PublishUnconfirmed as err:
                error, unconfirmed = str(err), True
            except VahrError as err:
                error = str(err)
            self.ledger.send(
                Sent(
                    command.id,
                    action,
                    (thing,),
                    path,
                    self._now(),
                    error=error,
                    unconfirmed=unconfirmed,
                )
            )

    def _skill_load(self) -> None:
        rng = random.Random(f"{self.config.seed}-skill")
        assert self.up is not None and self.swarm is not None
        api = self.up.endpoints["api"]
        everyone = (*AGENTS, *self.swarm.things)
        for tick in itertools.count():
            if not self._wait_tick(self.config.skill_interval_s, tick):
                return
            thing = rng.choice(AGENTS)
            zone = rng.choice(ZONES[:4])
            kind = rng.choices(["navigate", "deliver", "stop", "status", "fleet"], [4, 2, 1, 2, 1])[
                0
            ]
            utterance, action, targets = {
                "navigate": (f"send {SPOKEN[thing]} to zone {zone}", "navigate", (thing,)),
                "deliver": (
                    f"have {SPOKEN[thing]} deliver a package to zone {zone}",
                    "deliver",
                    (thing,),
                ),
                "stop": (f"stop {SPOKEN[thing]}", "stop", (thing,)),
                "status": (f"where is {SPOKEN[thing]}", "", ()),
                "fleet": (f"send all robots to zone {zone}", "navigate", everyone),
            }[kind]
            started = time.monotonic()
            try:
                turn = say(api, f"alexa ask robot fleet to {utterance}")
            except VahrError as err:
                self.turns.append(SkillTurn(utterance, time.monotonic() - started, "", str(err)))
                continue
            self.turns.append(
                SkillTurn(utterance, time.monotonic() - started, str(turn.get("speech") or ""))
            )
            for command_id in turn.get("commands") or []:
                self.ledger.send(Sent(command_id, action, targets, "skill", self._now()))

    def _now(self) -> float:
        return round(time.monotonic() - self._started, 3)

    # -- faults -----------------------------------------------------------------------

    def _inject_faults(self, deadline: float) -> None:
        rng = random.Random(f"{self.config.seed}-faults")
        order: list[str] = []
        for tick in itertools.count(1):
            due = self._started + tick * self.config.fault_interval_s
            if due >= deadline:
                break
            time.sleep(max(0.0, due - time.monotonic()))
            if time.monotonic() >= deadline - 1:
                break  # a slow recovery used up the time left
            if not order:  # every kind once per round, in a seeded order
                order = list(FAULTS)
                rng.shuffle(order)
            kind = order.pop(0)
            at = self._now()
            try:
                fault = {
                    "broker restart": self._restart_broker,
                    "robot-agent kill": lambda: self._kill_agent(rng.choice(AGENTS)),
                    "shadow pause": lambda: self._pause_shadows(rng.uniform(1.0, 3.0)),
                    "connection drop": self._drop_connections,
                }[kind]()
            except (TimeoutError, VahrError) as err:
                fault = Fault(kind, at, f"did not recover: {err}", survived=False)
            fault.at_s = at
            self.faults.append(fault)
        time.sleep(max(0.0, deadline - time.monotonic()))

    def _pids(self) -> dict[str, int]:
        found: dict[str, int] = {}
        for leftover in processes_of(self.state):
            try:
                argv = Path(f"/proc/{leftover.pid}/cmdline").read_bytes().split(b"\0")
            except OSError:
                continue
            words = [a.decode(errors="replace") for a in argv]
            if leftover.name == "mosquitto":
                found["mosquitto"] = leftover.pid
            elif "--thing" in words:
                found[words[words.index("--thing") + 1]] = leftover.pid
        if self.up is not None:
            found["vahr up"] = self.up.process.pid
        return found

    def _restart_broker(self) -> Fault:
        old = self._pids()["mosquitto"]
        kill_hard(old)
        killed_at = time.monotonic()
        # `vahr up` notices within half a second and starts it on the same persistence.
        wait_until(
            lambda: self._pids().get("mosquitto", old) != old and _accepts(self.mqtt_port), 30
        )
        back_at = time.monotonic()
        answered = self._ping_every_kind(timeout_s=RECOVERY_TIMEOUT_S)
        recovery = time.monotonic() - back_at
        return Fault(
            "broker restart",
            0.0,
            f"down {back_at - killed_at:.1f} s; pings answered: {answered}",
            survived=True,
            recovery_s=recovery,
        )

    def _ping_every_kind(self, timeout_s: float) -> str:
        """Ping both agents and the first swarm robot; return once each accepted it."""
        assert self.swarm is not None
        targets = [*AGENTS, self.swarm.things[0]]
        pending = {}
        publisher = _connect_when_possible(self.mqtt_port, timeout_s)
        try:
            for thing in targets:
                command = new_command("ping", source="console")
                publisher.publish(topics.robot_cmd(thing), encode(command))
                self.ledger.send(Sent(command.id, "ping", (thing,), "console", self._now()))
                pending[thing] = command.id
        finally:
            publisher.stop()

        missing: list[str] = []

        def answered() -> bool:
            records = self.ledger.records(self._agent_logs())
            missing[:] = [t for t, i in pending.items() if (t, i) not in records]
            return not missing

        try:
            wait_until(answered, timeout_s, poll_s=0.1)
        except TimeoutError:
            raise TimeoutError(
                f"no answer within {timeout_s:g} s from {', '.join(missing)}"
            ) from None
        return ", ".join(targets)

    def _kill_agent(self, thing: str) -> Fault:
        old = self._pids()[thing]
        kill_hard(old)
        self.kills[thing] += 1
        wait_until(lambda: self._pids().get(thing, old) != old, 30)
        return Fault("robot-agent kill", 0.0, f"{thing} killed, restarted by vahr up", True)

    def _pause_shadows(self, pause_s: float) -> Fault:
        assert self.up is not None
        pid = self.up.process.pid
        os.kill(pid, signal.SIGSTOP)
        try:
            time.sleep(pause_s)  # the pause is the fault
        finally:
            os.kill(pid, signal.SIGCONT)
        return Fault(
            "shadow pause",
            0.0,
            f"vahr up (shadows, data plane, skill) stopped {pause_s:.1f} s",
            survived=alive(pid),
        )

    def _drop_connections(self) -> Fault:
        relays = [r for r in (self.relay, self.console_relay) if r is not None]
        before = [r.accepted for r in relays]
        cut = [r.drop_all() for r in relays]
        # The swarm's link and the console's both come back through their relays. (A
        # relay's count of connections cut includes ones a broker restart already ended.)
        wait_until(
            lambda: all(r.accepted > b for r, b, c in zip(relays, before, cut, strict=True) if c),
            60,
        )
        return Fault("connection drop", 0.0, f"{sum(cut)} connections cut", survived=True)

    # -- afterwards -------------------------------------------------------------------

    def _agent_logs(self) -> list[Path]:
        return [self.state / "robots" / thing / "agent.log" for thing in AGENTS]

    def _settle(self) -> dict[tuple[str, str], Any]:
        """Wait until every owed command has ended (or the settle timeout passed)."""

        def records() -> dict[tuple[str, str], Any]:
            return self.ledger.records(self._agent_logs())

        with contextlib.suppress(TimeoutError):
            wait_until(
                lambda: self.ledger.settled(records()), self.config.settle_timeout_s, poll_s=1.0
            )
        return records()

    def _write_books(self, records: dict[tuple[str, str], Record]) -> None:
        """`{work_dir}/ledger.json`: every command sent, every fault and every robot's
        record, so a lost command can be followed through the logs after the run."""
        books = {
            "sent": [dataclasses.asdict(s) for s in self.ledger.sent],
            "faults": [dataclasses.asdict(f) for f in self.faults],
            "records": {f"{thing} {i}": r.events for (thing, i), r in records.items()},
        }
        (self.config.work_dir / "ledger.json").write_text(json.dumps(books, indent=1))

    def _check_shadows(self) -> tuple[list[str], int]:
        """Robots whose shadow still differs from the robot's own final state after 30 s."""
        assert self.up is not None and self.swarm is not None
        api = self.up.endpoints["api"]
        expected: dict[str, dict[str, Any]] = {}
        for thing in self.swarm.things:
            state = self.swarm.state(thing)
            last = state.last_command
            expected[thing] = {
                "status": state.status,
                "zone": state.zone,
                "cargo": state.cargo,
                "last_command": (last.id, last.result) if last else None,
            }
        for thing, path in zip(AGENTS, self._agent_logs(), strict=True):
            expected[thing] = {"last_command": read_agent_log(path)[1]}

        def differences() -> list[str]:
            wrong = []
            for thing, want in expected.items():
                try:
                    reported = call(api, "GET", f"/things/{thing}/shadow")["state"]["reported"]
                except (VahrError, KeyError) as err:
                    wrong.append(f"{thing}: {err}")
                    continue
                last = reported.get("last_command")
                seen = {
                    "status": reported.get("status"),
                    "zone": reported.get("zone"),
                    "cargo": reported.get("cargo"),
                    "last_command": (last["id"], last["result"]) if last else None,
                }
                for key, value in want.items():
                    if seen[key] != value:
                        wrong.append(f"{thing}: {key} {seen[key]!r} in the shadow, {value!r}")
                if thing in AGENTS and reported.get("status") in _MOVING:
                    wrong.append(f"{thing}: status {reported.get('status')} after it settled")
            return wrong

        found: list[str] = []

        def converged() -> bool:
            nonlocal found
            found = differences()
            return not found

        with contextlib.suppress(TimeoutError):
            wait_until(converged, 30, poll_s=1.0)
        return found, len(expected)

    def _check_alive(self) -> None:
        assert self.up is not None and self.swarm is not None
        if self.up.process.poll() is not None:
            self.crashes.append(f"vahr up exited with {self.up.process.returncode}")
        errors = (self.state / "up.err").read_text(errors="replace")
        for thing in AGENTS:
            restarts = len(re.findall(rf"robot {thing} stopped unexpectedly", errors))
            if restarts != self.kills[thing]:
                self.crashes.append(
                    f"{thing} stopped {restarts} times, {self.kills[thing]} of them killed here"
                )
        broker_restarts = len(re.findall("the MQTT broker stopped unexpectedly", errors))
        killed = sum(1 for f in self.faults if f.kind == "broker restart")
        if broker_restarts != killed:
            self.crashes.append(f"mosquitto stopped {broker_restarts} times, {killed} killed")
        self.crashes += [f"skill request failed: {t.error}" for t in self.turns if t.error]

    def _sample_memory(self) -> None:
        while not self._stop_load.wait(self.config.sample_interval_s):
            for role, pid in self._pids().items():
                key = "robot-agent" if role in AGENTS else role
                size = _rss_mb(pid)
                if size is not None:
                    self.rss.setdefault(key, []).append(size)
            own = _rss_mb(os.getpid())
            if own is not None:
                self.rss.setdefault("swarm", []).append(own)


_MOVING = frozenset({"navigating", "loading", "unloading", "waiting"})


def _rss_mb(pid: int) -> float | None:
    try:
        for line in Path(f"/proc/{pid}/status").read_text().splitlines():
            if line.startswith("VmRSS:"):
                return int(line.split()[1]) / 1024
    except OSError:
        return None
    return None


def _accepts(port: int) -> bool:
    import socket

    with contextlib.suppress(OSError), socket.create_connection(("127.0.0.1", port), timeout=1):
        return True
    return False


def _connect_when_possible(port: int, timeout_s: float) -> MqttClient:
    deadline = time.monotonic() + timeout_s
    while True:
        try:
            return MqttClient(MqttEndpoint(port=port)).connect()
        except VahrError:
            if time.monotonic() > deadline:
                raise
            time.sleep(0.1)


def run_soak(config: SoakConfig) -> SoakReport:
    return Soak(config).run()


def summary(report: SoakReport) -> dict[str, Any]:
    """The figures of a run, for the test's message and the benchmark's table."""
    v = report.verdict
    latencies = [t.latency_s for t in report.turns if not t.error]
    return {
        "minutes": round(report.elapsed_s / 60, 1),
        "commands owed": v.owed,
        "executed once": v.executed,
        "reported": dict(v.reported),
        "replaced in desired state": v.replaced_in_desired,
        "lost": len(v.lost),
        "run twice": len(v.run_twice),
        "refused at source": v.refused_at_source,
        "ran after refusal": len(v.ran_after_refusal),
        "unconfirmed at source (ran)": f"{v.unconfirmed} ({v.unconfirmed_ran})",
        "unknown ids": len(v.unknown),
        "faults": {k: sum(1 for f in report.faults if f.kind == k) for k in FAULTS},
        "faults survived": sum(1 for f in report.faults if f.survived),
        "skill turns": len(report.turns),
        "skill p50 s": round(statistics.median(latencies), 3) if latencies else None,
        "skill max s": round(max(latencies), 3) if latencies else None,
        "slow or invalid turns": len(report.slow_or_invalid_turns),
        "unconverged shadows": len(report.unconverged),
        "rss MB": {r: (round(a), round(b)) for r, (a, b) in report.rss_mb.items()},
        "longest recovery s": report.longest_recovery_s,
        "crashes": report.crashes,
    }
