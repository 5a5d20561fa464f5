"""robot-agent on ROS 2: command -> Nav2 goal accepted, and the agent's idle cost with rclpy.

Starts a real mosquitto on loopback, the stand-in bt_navigator (`tests/support/nav2_stand_in.py`,
a real rclpy NavigateToPose server over Fast DDS, not Nav2) and a real
`.venv-ros2/bin/robot-agent run --backend nav2`, then measures:

1. the time from a client publishing a `navigate` command to the stand-in's goal callback
   receiving the goal and to the goal being accepted (both clocks are this machine's
   CLOCK_MONOTONIC, read in the two processes), p50 and p95 over `--commands` commands,
   each sent once the previous goal succeeded;
2. the agent's CPU while idle for `--idle-seconds` and its resident memory, beside the same
   agent with the sim backend (no rclpy) measured in the same run.

DDS stays on loopback: run as root, the script re-runs itself in a private network
namespace (`unshare -n`); discovery is limited to localhost and the domain is its own.
Needs `.venv-ros2` (make setup).
"""

from __future__ import annotations

import argparse
import os
import shlex
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from _results import median, percentile, write_section
from agent_footprint import THING, Probe, cpu_seconds, rss_mb

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from tests.support.nav2 import Nav2StandIn, isolate_ros2, next_domain_id  # noqa: E402
from vahr.plumbing.ports import free_port  # noqa: E402
from vahr.twin.broker import BrokerConfig, Mosquitto  # noqa: E402

ROS2_BIN = ROOT / ".venv-ros2" / "bin"
ISOLATED = "VAHR_BENCH_NETNS"


def isolate() -> None:
    """Run again inside a private network namespace when this process may make one."""
    if os.environ.get(ISOLATED) or os.geteuid() != 0:
        return
    argv = " ".join(map(shlex.quote, [sys.executable, *sys.argv]))
    command = f"ip link set lo up && exec {argv}"
    os.environ[ISOLATED] = "1"
    os.execvp("unshare", ["unshare", "-n", "sh", "-c", command])


def start_agent(executable: Path, port: int, state: Path, *extra: str) -> subprocess.Popen[bytes]:
    return subprocess.Popen(
        [str(executable), "run", "--thing", THING, "--broker", f"mqtt://127.0.0.1:{port}",
         "--state-dir", str(state), "--log-level", "WARNING", *extra],
        stdin=subprocess.DEVNULL,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )  # fmt: skip


def stop(agent: subprocess.Popen[bytes]) -> None:
    if agent.poll() is None:
        agent.terminate()
        try:
            agent.wait(timeout=20)
        except subprocess.TimeoutExpired:
            agent.kill()
            agent.wait(timeout=5)


def idle_cost(agent: subprocess.Popen[bytes], seconds: float) -> tuple[float, float]:
    """(% of one core, resident MB) of `agent` doing nothing for `seconds`."""
    time.sleep(2)  # let start-up work (imports, first reports) settle
    cpu_before, wall_before = cpu_seconds(agent.pid), time.monotonic()
    time.sleep(seconds)
    used = cpu_seconds(agent.pid) - cpu_before
    return 100 * used / (time.monotonic() - wall_before), rss_mb(agent.pid)


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--idle-seconds", type=float, default=30.0)
    parser.add_argument("--commands", type=int, default=100)
    parser.add_argument("--no-write", action="store_true", help="print, do not update docs")
    args = parser.parse_args()
    if not (ROS2_BIN / "robot-agent").exists():
        print("bench/nav2_goal_latency.py: no .venv-ros2 (run make setup)", file=sys.stderr)
        return 2
    isolate()

    received: list[float] = []
    accepted: list[float] = []
    with tempfile.TemporaryDirectory(prefix="vahr-bench-nav2-") as tmp:
        home = Path(tmp)
        isolate_ros2(home)
        broker = Mosquitto(BrokerConfig(state_dir=home / "broker", plain_port=free_port()))
        broker.start()
        port = broker.config.plain_port or 0
        stand_in = Nav2StandIn(
            home / "stand-in", domain_id=next_domain_id(), python=str(ROS2_BIN / "python")
        )
        probe = Probe(port)
        agents: list[subprocess.Popen[bytes]] = []
        try:
            # The sim backend's agent first, alone, for the comparison.
            sim = start_agent(ROOT / ".venv" / "bin" / "robot-agent", port, home / "sim")
            agents.append(sim)
            probe.wait_online(15)
            sim_cpu, sim_rss = idle_cost(sim, args.idle_seconds)
            stop(sim)
            probe.close()

            stand_in.start()
            stand_in.plan(default={"mode": "succeed", "steps": 2, "step_s": 0.01})
            config = home / "nav2.yaml"
            config.write_text(f"nav2:\n  domain_id: {stand_in.domain_id}\n")
            probe = Probe(port)  # hears the nav2 agent come online
            nav2 = start_agent(
                ROS2_BIN / "robot-agent", port, home / "nav2", "--backend", "nav2",
                "--config", str(config),
            )  # fmt: skip
            agents.append(nav2)
            probe.wait_online(30)
            nav2_cpu, nav2_rss = idle_cost(nav2, args.idle_seconds)
            zones = ["B", "C"]
            for i in range(args.commands + 5):
                goals, succeeded = len(stand_in.seen("goal")), len(stand_in.seen("succeeded"))
                sent = time.monotonic()
                probe.round_trip("navigate", {"zone": zones[i % 2]})
                goal = stand_in.wait_for("goal", goals + 1)
                accept = stand_in.wait_for("accepted", goals + 1)
                stand_in.wait_for("succeeded", succeeded + 1)
                if i >= 5:  # the first goals warm up discovery and the agent's paths
                    received.append((goal["at"] - sent) * 1000)
                    accepted.append((accept["at"] - sent) * 1000)
                time.sleep(0.05)  # the agent reports arrival and done
            busy_rss = rss_mb(nav2.pid)
        finally:
            for agent in agents:
                stop(agent)
            probe.close()
            stand_in.stop()
            broker.stop()

    def row(name: str, values: list[float]) -> str:
        return (
            f"| {name} | {len(values)} | {median(values):.1f} | {percentile(values, 95):.1f} "
            f"| {max(values):.1f} |"
        )

    body = f"""
`robot-agent run --backend nav2` from `.venv-ros2` (ROS 2 Jazzy from PyPI: rclpy 7.1.6, Fast
DDS 2.14.5) against the stand-in bt_navigator (a real rclpy NavigateToPose server in its
own process, not Nav2), over a real mosquitto, in a private network namespace with
localhost discovery. Commands are sent one at a time, each once the previous goal
succeeded; the first 5 are left out (discovery, first calls).

Command published on `vahr/robots/{THING}/cmd` -> the NavigateToPose goal at the server:

| step | n | p50 ms | p95 ms | max ms |
| --- | --- | --- | --- | --- |
{row("goal received (goal callback)", received)}
{row("goal accepted", accepted)}

The agent idle for {args.idle_seconds:g} s, with the nav2 backend (an rclpy node, its
spinning thread and a Fast DDS participant) and, in the same run, with the sim backend:

| backend | idle CPU (% of one core) | resident memory, idle |
| --- | --- | --- |
| sim (`.venv`) | {sim_cpu:.3f} % | {sim_rss:.1f} MB |
| nav2 (`.venv-ros2`) | {nav2_cpu:.3f} % | {nav2_rss:.1f} MB |

Resident memory of the nav2 agent after the {args.commands + 5} goals: {busy_rss:.1f} MB.
"""
    if args.no_write:
        print(body)
    else:
        write_section("nav2_goal_latency", "robot-agent on ROS 2 (Nav2)", body)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
