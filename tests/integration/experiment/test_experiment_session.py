"""A whole session over a real broker: the simulated participant clicks in the console,
`robot-agent run` processes deliver, the log records the wire, the judge scores, the report follows."""

from __future__ import annotations

import json
from typing import TYPE_CHECKING, Any

from tests.integration.experiment.experiment_robots import SPEED, robot_agents
from vahr.cli import main
from vahr.experiment.eventlog import Kind, read_log

__all__ = ["robot_agents"]  # the fixture, used by name

if TYPE_CHECKING:
    from pathlib import Path

    import pytest

    from tests.integration.experiment.experiment_robots import RobotAgents
    from vahr.local.broker import Mosquitto


def test_keyboard_session_runs_all_three_tasks_and_reports(
    tmp_path: Path,
    mosquitto: Mosquitto,
    robot_agents: RobotAgents,
    capsys: pytest.CaptureFixture[str],
) -> None:
    # Given robots on a real broker and a simulated participant using the console
    logs = tmp_path / "logs"
    argv = [
        "experiment",
        "--participant",
        "SIM01",
        "--method",
        "keyboard",
        "--trial",
        "1",
        "--seed",
        "11",
        "--log-dir",
        str(logs),
        "--broker",
        mosquitto.plain_url,
        "--no-shadow",
        "--simulate",
        "--speed-factor",
        str(SPEED),
        "--json",
    ]
    # When the session runs
    assert main(argv) == 0
    summary = json.loads(capsys.readouterr().out)
    # Then every task succeeded as the judge defines it, and task III lit the LED
    tasks = summary["verdict"]["tasks"]
    assert {task: body["success"] for task, body in tasks.items()} == {
        "I": True,
        "II": True,
        "III": True,
    }, tasks
    assert tasks["III"]["led_on"] is True
    assert summary["verdict"]["command_success"]["success_rate"] == 1.0
    plan = summary["plan"]
    assert {d["thing"]: d["zone"] for d in tasks["I"]["deliveries"]} == plan["assignments"]
    # and the log holds the console's commands as seen on the wire, source "console"
    entries = read_log(logs / "SIM01-keyboard-trial1.sqlite")
    commands = [e.data for e in entries if e.kind == Kind.COMMAND]
    assert [c["action"] for c in commands] == [
        "deliver",
        "deliver",
        "deliver",
        "deliver",
        "sequential_delivery",
    ]
    assert {c["source"] for c in commands} == {"console"}
    # and in task III placebot2 waited for placebot1, as robots coordinating among themselves
    waiting = [
        e.data["thing"]
        for e in entries
        if e.kind == Kind.ROBOT_EVENT and e.task == "III" and e.data["event"] == "waiting"
    ]
    assert waiting == ["placebot2"]
    assert entries[-1].kind == Kind.SESSION_ENDED

    # When the participant's questionnaire is entered and the report is made from the logs
    levels = [
        "--mental",
        "6",
        "--physical",
        "3",
        "--temporal",
        "9",
        "--performance",
        "17",
        "--effort",
        "7",
        "--frustration",
        "4",
        "--confidence",
        "15",
        "--trust",
        "14",
    ]
    assert (
        main(
            [
                "tlx",
                "--participant",
                "SIM01",
                "--method",
                "keyboard",
                "--trial",
                "1",
                "--log-dir",
                str(logs),
                *levels,
            ]
        )
        == 0
    )
    out = tmp_path / "report"
    assert main(["report", "--from-log", str(logs), "--out", str(out)]) == 0
    # Then the report has the run's measured times (in experiment seconds) and its figures
    report = json.loads((out / "report.json").read_text())
    assert report["simulated"] is True
    means = report["objective"]
    ie, nt = (
        means["interaction_time"]["means"]["keyboard"],
        means["neglect_time"]["means"]["keyboard"],
    )
    # Five commands of four clicks each, by the keystroke-level model: about 6.5 s each.
    assert 20 < ie < 60
    assert nt > 0
    assert means["rad"]["means"]["keyboard"] == ie / (ie + nt)
    assert report["subjective"]["mental"]["means"]["keyboard"] == 25.0
    assert report["success"]["task"]["keyboard"] == {
        "successes": 3,
        "total": 3,
        "success_rate": 1.0,
    }
    assert report["success"]["command"]["keyboard"]["success_rate"] == 1.0
    (session,) = json.loads((out / "sessions.json").read_text())
    assert session["session"] == "SIM01-keyboard-trial1" and session["finished"] is True
    assert session["verdict"]["tasks"]["III"]["led_on"] is True
    assert set(session["times"]["tasks"]) == {"I", "II", "III"}
    assert "Simulated participants" in (out / "report.md").read_text()
    for name in ("subjective.png", "tlx_by_trial.png", "objective.png"):
        assert (out / name).stat().st_size > 1000


def test_a_session_cut_mid_task_resumes_without_repeating_or_losing_anything(
    tmp_path: Path,
    mosquitto: Mosquitto,
    robot_agents: RobotAgents,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
) -> None:
    from vahr.experiment.participant import SimulatedParticipant

    logs = tmp_path / "logs"
    argv = [
        "experiment",
        "--participant",
        "SIM02",
        "--method",
        "keyboard",
        "--trial",
        "1",
        "--seed",
        "5",
        "--log-dir",
        str(logs),
        "--broker",
        mosquitto.plain_url,
        "--no-shadow",
        "--simulate",
        "--speed-factor",
        str(SPEED),
        "--json",
    ]
    # Given a session interrupted (Ctrl-C) in task I, after its first click sequence
    original = SimulatedParticipant._click
    clicks: list[str] = []

    def interrupted(self: SimulatedParticipant, task: str, click: Any) -> None:
        clicks.append(task)
        if clicks.count("I") == 2:
            raise KeyboardInterrupt
        original(self, task, click)

    monkeypatch.setattr(SimulatedParticipant, "_click", interrupted)
    assert main(argv) == 130
    path = logs / "SIM02-keyboard-trial1.sqlite"
    before = read_log(path)
    assert [e.data["task"] for e in before if e.kind == Kind.TASK_ENDED] == []
    assert [e.kind for e in before].count(Kind.INTERACTION_ENDED) == 1
    # When it is started again
    monkeypatch.setattr(SimulatedParticipant, "_click", original)
    capsys.readouterr()
    assert main(argv) == 0
    summary = json.loads(capsys.readouterr().out)
    # Then it resumed: task I's first click was not repeated, and every task succeeded
    after = read_log(path)
    assert after[: len(before)] == before
    assert summary["resumed"] is True
    assert [e.kind for e in after].count(Kind.SESSION_RESUMED) == 1
    sent = [e.data["action"] for e in after if e.kind == Kind.COMMAND]
    assert sent == ["deliver", "deliver", "deliver", "deliver", "sequential_delivery"]
    assert all(body["success"] for body in summary["verdict"]["tasks"].values()), summary


def test_an_observed_keyboard_session_with_a_person_at_the_console(
    tmp_path: Path,
    mosquitto: Mosquitto,
    robot_agents: RobotAgents,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
) -> None:
    import os
    import threading
    import time

    from vahr.experiment.tasks import draw_plan
    from vahr.protocol import load_fleet

    logs = tmp_path / "logs"
    plan = draw_plan(load_fleet(), 21)
    path = logs / "P05-keyboard-trial2.sqlite"
    # What the observer types during each task: the participant's clicks and puzzle pieces
    typed = {
        "I": ["p", *[f"send {t} deliver {z}" for t, z in plan.assignments.items()], "p 2"],
        "II": [f"send placebot1 deliver {'A' if plan.weather == 'sunny' else 'C'}"],
        "III": ["k", "send placebot1 deliver D", "send placebot2 sequential_delivery D placebot1"],
    }
    read_end, write_end = os.pipe()
    stop = threading.Event()

    def observer_types() -> None:
        done: set[str] = set()
        while not stop.is_set() and len(done) < 3:
            started = (
                [e.data["task"] for e in read_log(path) if e.kind == Kind.TASK_STARTED]
                if path.exists()
                else []
            )
            for task in started:
                if task not in done:
                    done.add(task)
                    os.write(write_end, "".join(f"{line}\n" for line in typed[task]).encode())
            time.sleep(0.05)

    typist = threading.Thread(target=observer_types)
    typist.start()
    try:
        with os.fdopen(read_end) as keyboard:
            monkeypatch.setattr("sys.stdin", keyboard)
            # When a session with a person runs (no --simulate), the observer at the keyboard
            code = main(
                [
                    "experiment",
                    "--participant",
                    "P05",
                    "--method",
                    "keyboard",
                    "--trial",
                    "2",
                    "--seed",
                    "21",
                    "--log-dir",
                    str(logs),
                    "--broker",
                    str(mosquitto.plain_url),
                    "--no-shadow",
                    "--task-timeout",
                    "30",
                    "--json",
                ]
            )
    finally:
        stop.set()
        typist.join(10)
        os.close(write_end)
    assert code == 0
    summary = json.loads(capsys.readouterr().out)
    # Then the console's clicks drove the robots and every task succeeded
    assert summary["simulated"] is False
    assert all(body["success"] for body in summary["verdict"]["tasks"].values()), summary
    entries = read_log(path)
    assert sum(e.data.get("count", 0) for e in entries if e.kind == Kind.OBSERVER) == 3
    clicks = [e.data for e in entries if e.kind == Kind.INTERACTION_ENDED]
    assert len(clicks) == 5 and all(c["channel"] == "click" and c["commands"] for c in clicks)
