"""`robot-agent swarm` refuses a count its fleet cannot give, in one line, before it
connects anywhere."""

from __future__ import annotations

import subprocess
import sys

import pytest

from vahr.domain import load_fleet


@pytest.mark.parametrize("count", ["0", "-1", "3"])
def test_a_count_outside_the_fleet_is_one_line_and_exit_code_2(count: str) -> None:
    robots = len(load_fleet().robots)
    result = subprocess.run(
        [sys.executable, "-m", "robot_agent.cli", "swarm", "--count", count,
         "--broker", "mqtt://127.0.0.1:1"],
        capture_output=True, text=True, timeout=60,
    )  # fmt: skip
    assert result.returncode == 2
    assert result.stderr == (
        f"robot-agent swarm: error: --count {count}: the fleet has {robots} robots; "
        f"give 1 to {robots}\n"
    )


def test_a_plaintext_broker_off_this_machine_is_refused() -> None:
    result = subprocess.run(
        [sys.executable, "-m", "robot_agent.cli", "swarm", "--broker", "mqtt://10.1.2.3:1883"],
        capture_output=True, text=True, timeout=60,
    )  # fmt: skip
    assert result.returncode == 2
    assert "plaintext MQTT is allowed only to a loopback broker" in result.stderr
    assert result.stderr.count("\n") == 1
