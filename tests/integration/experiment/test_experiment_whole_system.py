"""The paper's experiment end to end on the whole local system (`vahr up`): the simulated
participant runs all three tasks with each method, and the report comes out with figures."""

from __future__ import annotations

import json
import signal
import subprocess
import sys
import time
from typing import TYPE_CHECKING, Any

import pytest

from vahr.cli import main
from vahr.plumbing.lifetime import spawn
from vahr.plumbing.ports import free_port

if TYPE_CHECKING:
    from collections.abc import Iterator
    from pathlib import Path

SPEED = 20.0
START_TIMEOUT_S = 60.0


@pytest.fixture
def system(tmp_path: Path) -> Iterator[dict[str, Any]]:
    """`vahr up --json` on free ports, faster than real time; yields its endpoints.

    Its output goes to a file: it prints a line per robot event, and a pipe nobody reads
    would fill up and stall it.
    """
    out_file, err_file = tmp_path / "up.out", tmp_path / "up.err"
    with out_file.open("wb") as out, err_file.open("wb") as err:
        process = spawn(
            [
                sys.executable,
                "-m",
                "vahr.cli",
                "up",
                "--json",
                "--state-dir",
                str(tmp_path / "state"),
                "--api-port",
                str(free_port()),
                # `vahr experiment` records from the plaintext development listener.
                "--dev-plaintext",
                "--mqtt-port",
                str(free_port()),
                "--mqtts-port",
                str(free_port()),
                "--station-port",
                "0",
                "--sim-speed-factor",
                str(SPEED),
            ],
            started_for=tmp_path / "state",
            stdout=out,
            stderr=err,
            stdin=subprocess.DEVNULL,
        )
    try:
        deadline = time.monotonic() + START_TIMEOUT_S
        while b"\n" not in out_file.read_bytes():
            assert process.poll() is None, f"vahr up exited: {err_file.read_text()[-500:]}"
            assert time.monotonic() < deadline, f"vahr up printed nothing; see {err_file}"
            time.sleep(0.1)
        yield json.loads(out_file.read_bytes().split(b"\n", 1)[0])
    finally:
        process.send_signal(signal.SIGTERM)
        try:
            process.wait(30)
        except subprocess.TimeoutExpired:
            process.kill()
            process.wait(10)


def test_both_methods_run_all_three_tasks_and_the_report_has_figures(
    tmp_path: Path, system: dict[str, Any], capsys: pytest.CaptureFixture[str]
) -> None:
    logs = tmp_path / "logs"
    verdicts = {}
    for method in ("vahr", "keyboard"):
        # When the simulated participant runs a session with each method
        code = main(
            [
                "experiment",
                "--participant",
                "SIM",
                "--method",
                method,
                "--trial",
                "1",
                "--seed",
                "3",
                "--log-dir",
                str(logs),
                "--broker",
                system["mqtt"],
                "--api",
                system["api"],
                "--simulate",
                "--speed-factor",
                str(SPEED),
                "--task-timeout",
                "900",
                "--json",
            ]
        )
        assert code == 0
        verdicts[method] = json.loads(capsys.readouterr().out)["verdict"]
    # Then every task succeeded with both methods, task III in order with the LED lit
    for method, verdict in verdicts.items():
        tasks = verdict["tasks"]
        assert all(tasks[task]["success"] for task in ("I", "II", "III")), (method, tasks)
        third = tasks["III"]
        assert third["led_on"] is True
        assert [(d["thing"], d["zone"]) for d in third["deliveries"]] == [
            ("placebot1", "D"),
            ("placebot2", "D"),
        ], third
    # and with the voice method each robot asked the assistant for the weather and
    # understood: four navigation orders, two weather navigations, one sequential delivery
    # said by the participant, and the two robots' own exchanges
    voice = verdicts["vahr"]["communication_success"]
    assert voice["success_rate"] == 1.0 and voice["total"] == 9, voice
    # while with the keyboard and mouse the participant asked for the weather twice and
    # clicked twelve navigation orders, every one answered or acknowledged
    keyboard = verdicts["keyboard"]["communication_success"]
    assert keyboard["success_rate"] == 1.0 and keyboard["total"] == 14, keyboard
    # When the report is made from the two sessions' logs
    out = tmp_path / "report"
    assert main(["report", "--from-log", str(logs), "--out", str(out)]) == 0
    # Then it compares the methods, labelled simulated, with its figures
    report = json.loads((out / "report.json").read_text())
    assert report["methods"] == ["vahr", "keyboard"] and report["simulated"] is True
    for metric in ("interaction_time", "neglect_time", "rad", "fan_out", "time_taken"):
        assert set(report["objective"][metric]["means"]) == {"vahr", "keyboard"}
    for name in ("objective.png", "objective.svg", "trial_change.png"):
        assert (out / name).stat().st_size > 1000
    assert not (out / "subjective.png").exists()  # simulated runs answer no questionnaire
