"""`robot-agent run` configuration: precedence, --print-config, and one-line errors."""

from __future__ import annotations

import importlib.util
import json
from typing import TYPE_CHECKING

import pytest

from robot_agent.cli import main

if TYPE_CHECKING:
    from pathlib import Path


@pytest.fixture(autouse=True)
def clean_environment(monkeypatch: pytest.MonkeyPatch) -> None:
    import os

    for name in list(os.environ):
        if name.startswith("VAHR_AGENT_"):
            monkeypatch.delenv(name)


def printed_config(capsys: pytest.CaptureFixture[str], *argv: str) -> dict[str, object]:
    assert main(["run", *argv, "--print-config"]) == 0
    loaded: dict[str, object] = json.loads(capsys.readouterr().out)
    return loaded


def error_of(capsys: pytest.CaptureFixture[str], *argv: str) -> str:
    assert main(["run", *argv]) == 2
    lines = capsys.readouterr().err.strip().splitlines()
    assert len(lines) == 1, lines
    return lines[0]


def test_flags_beat_environment_beat_file_beat_defaults(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    config = tmp_path / "agent.yaml"
    config.write_text(
        "thing: placebot2\nbroker: mqtt://127.0.0.1:1999\nsim_speed_factor: 3\n"
        "log_level: DEBUG\nexecutor:\n  stuck_after_s: 42\n"
    )
    monkeypatch.setenv("VAHR_AGENT_SIM_SPEED_FACTOR", "7")
    monkeypatch.setenv("VAHR_AGENT_LOG_LEVEL", "WARNING")
    shown = printed_config(capsys, "--config", str(config), "--log-level", "ERROR")
    assert shown["thing"] == "placebot2"  # file
    assert shown["sim_speed_factor"] == 7.0  # environment over file
    assert shown["log_level"] == "ERROR"  # flag over environment
    assert shown["executor"] == {
        "stuck_after_s": 42.0,
        "sequential_timeout_s": 300.0,
        "peer_clock_skew_s": 2.0,
        "listen_timeout_s": 8.0,
        "speak_timeout_s": 30.0,
        "progress_interval_s": 5.0,
        "progress_step": 0.25,
    }
    assert shown["backend"] == "sim" and shown["port"] == 8883  # defaults


def test_the_progress_rate_is_chosen_by_file_or_environment(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    # Given a deployment that wants a report every 2 s (file) on every tenth (environment)
    config = tmp_path / "agent.yaml"
    config.write_text(
        "thing: placebot1\nbroker: mqtt://127.0.0.1:1999\n"
        "executor:\n  progress_interval_s: 2\n  progress_step: 0.5\n"
    )
    monkeypatch.setenv("VAHR_AGENT_PROGRESS_STEP", "0.1")
    # When the agent reads its configuration
    shown = printed_config(capsys, "--config", str(config))
    # Then both apply, the environment over the file
    executor = shown["executor"]
    assert isinstance(executor, dict)
    assert (executor["progress_interval_s"], executor["progress_step"]) == (2.0, 0.1)


def test_an_unknown_key_in_the_file_is_named(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    config = tmp_path / "agent.yaml"
    config.write_text("thing: placebot1\nsim:\n  warp: 9\n")
    assert error_of(capsys, "--config", str(config)) == (
        "robot-agent run: error: configuration: sim.warp: is not a known field"
    )


@pytest.mark.parametrize(
    ("section", "message"),
    [
        ("sim:\n  turn_rate_rps: 0\n", "sim.turn_rate_rps: expected `float` > 0.0"),
        ("sim:\n  speed_mps: -1\n", "sim.speed_mps: expected `float` > 0.0"),
        ("executor:\n  stuck_after_s: 0\n", "executor.stuck_after_s: expected `float` > 0.0"),
        ("ros:\n  loader_delay_s: -3\n", "ros.loader_delay_s: expected `float` >= 0.0"),
        ("executor:\n  progress_step: 1.5\n", "executor.progress_step: expected `float` <= 1.0"),
    ],
)
def test_a_number_out_of_range_in_the_file_is_named(
    section: str, message: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # Given a setting no robot could run with (a zero turn rate divides by zero)
    config = tmp_path / "agent.yaml"
    config.write_text("thing: placebot1\n" + section)
    # Then the agent refuses to start and names the key
    assert error_of(capsys, "--config", str(config)) == (
        f"robot-agent run: error: configuration: {message}"
    )


def test_a_bad_environment_value_is_named(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    monkeypatch.setenv("VAHR_AGENT_SIM_SPEED_FACTOR", "fast")
    assert error_of(capsys, "--thing", "placebot1").startswith(
        "robot-agent run: error: configuration: sim_speed_factor: expected float"
    )


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        ((), "--thing is required (or `thing` in --config, or VAHR_AGENT_THING)"),
        (
            ("--thing", "placebot1"),
            "give --endpoint with --cert, --key and --ca, or --broker mqtt://127.0.0.1:PORT",
        ),
        (
            ("--thing", "placebot1", "--broker", "mqtt://127.0.0.1:1", "--endpoint", "x"),
            "give either --broker (plaintext loopback) or --endpoint (mTLS), not both",
        ),
        (
            ("--thing", "placebot1", "--endpoint", "example.com"),
            "--endpoint needs --cert and --key",
        ),
        (
            (
                "--thing",
                "placebot1",
                "--endpoint",
                "example.com",
                "--cert",
                "/no/cert.pem",
                "--key",
                "/no/key",
            ),
            "--cert /no/cert.pem: no such file",
        ),
        (
            ("--thing", "placebot1", "--broker", "mqtt://10.0.0.5:1883"),
            "--broker 'mqtt://10.0.0.5:1883': plaintext MQTT is allowed only to a loopback broker; use --endpoint with --cert, --key and --ca for any other host",
        ),
        (
            ("--thing", "placebot1", "--broker", "http://127.0.0.1:1883"),
            "--broker 'http://127.0.0.1:1883': expected mqtt://127.0.0.1:PORT",
        ),
        (
            ("--thing", "robot9", "--broker", "mqtt://127.0.0.1:1"),
            "--thing robot9: not a robot of the fleet; robots are placebot1, placebot2",
        ),
        (
            ("--thing", "placebot1", "--endpoint", "example.com", "--port", "70000"),
            "--port 70000: expected a TCP port (1-65535)",
        ),
        (
            ("--thing", "placebot1", "--broker", "mqtt://127.0.0.1:1", "--sim-speed-factor", "0"),
            "--sim-speed-factor must be greater than 0",
        ),
        (
            ("--thing", "placebot1", "--broker", "mqtt://127.0.0.1:1", "--sim-speed-factor", "nan"),
            "--sim-speed-factor must be greater than 0",
        ),
        (
            ("--thing", "placebot1", "--broker", "mqtt://127.0.0.1:1", "--sim-speed-factor", "inf"),
            "--sim-speed-factor must be greater than 0",
        ),
        (
            ("--thing", "placebot1", "--broker", "mqtt://[::1"),
            "--broker 'mqtt://[::1': Invalid IPv6 URL",
        ),
        (
            (
                "--thing",
                "placebot1",
                "--broker",
                "mqtt://127.0.0.1:1",
                "--backend",
                "ros1",
                "--sim-speed-factor",
                "5",
            ),
            "--sim-speed-factor applies to the sim backend only; ROS runs in real time",
        ),
        (
            (
                "--thing",
                "placebot1",
                "--broker",
                "mqtt://127.0.0.1:1",
                "--backend",
                "nav2",
                "--sim-speed-factor",
                "5",
            ),
            "--sim-speed-factor applies to the sim backend only; ROS runs in real time",
        ),
        (
            ("--thing", "placebot1", "--broker", "mqtt://127.0.0.1:1", "--voice", "nonsense"),
            "--voice 'nonsense': expected none or package.module:factory",
        ),
        (
            ("--thing", "placebot1", "--broker", "mqtt://127.0.0.1:1", "--voice", "json:decoder"),
            "--voice 'json:decoder': decoder is not a factory",
        ),
        (
            ("--thing", "placebot1", "--broker", "mqtt://127.0.0.1:1", "--voice", "json:dumps"),
            "--voice 'json:dumps': not a factory taking thing= "
            "(missing a required argument: 'obj')",
        ),
    ],
)
def test_bad_settings_are_one_line_errors(
    argv: tuple[str, ...], message: str, capsys: pytest.CaptureFixture[str]
) -> None:
    assert error_of(capsys, *argv) == f"robot-agent run: error: {message}"


def test_a_certificate_that_is_not_pem_is_a_one_line_error(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # Given certificate and key files that exist but hold no PEM
    cert, key = tmp_path / "cert.pem", tmp_path / "private.key"
    cert.write_text("not a certificate\n")
    key.write_text("not a key\n")
    # Then the agent stops before connecting, with one line naming what failed
    error = error_of(
        capsys, "--thing", "placebot1", "--endpoint", "localhost", "--cert", str(cert),
        "--key", str(key),
    )  # fmt: skip
    assert error.startswith("robot-agent run: error: cannot load the certificate, key or CA: ")


@pytest.mark.skipif(
    importlib.util.find_spec("rclpy") is not None, reason="this venv has ROS 2 (.venv-ros2)"
)
def test_the_nav2_backend_outside_a_ros2_venv_is_a_one_line_error(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # Given the main venv, which has ROS 1 and not ROS 2
    # When the agent is started with the nav2 backend
    error = error_of(
        capsys, "--thing", "placebot1", "--broker", "mqtt://127.0.0.1:1", "--backend", "nav2",
        "--state-dir", str(tmp_path),
    )  # fmt: skip
    # Then it stops before connecting, saying where ROS 2 is
    assert error == (
        "robot-agent run: error: --backend nav2 needs ROS 2's rclpy and nav2_msgs (No module "
        "named 'rclpy'); run robot-agent from .venv-ros2 (make setup makes it), or next to the "
        "robot's own ROS 2"
    )
