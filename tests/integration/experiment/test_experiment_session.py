"""A whole session over a real broker: the simulated participant clicks in the console,
`robot-agent run` processes deliver, the log records the wire, the judge scores, the report follows."""

from __future__ import annotations

import json
from typing import TYPE_CHECKING, Any

from tests.integration.experiment.experiment_robots import SPEED, lab
from vahr.cli import main
from vahr.experiment.eventlog import Kind, read_log

__all__ = ["lab"]  # the fixture, used by name

if TYPE_CHECKING:
    from pathlib import Path

    import pytest

    from tests.integration.experiment.experiment_robots import Lab


def test_keyboard_session_runs_all_three_tasks_and_reports(
    tmp_path: Path,
    lab: Lab,
    capsys: pytest.CaptureFixture[str],
) -> None:
    # Given robots on the local stack and a simulated participant using the panel
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
        lab.broker_url,
        "--api",
        lab.api_url,
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
    # and the log holds the panel's orders as seen on the wire: navigation only, source
    # "console", two per robot and task (to the loading zone, then on)
    entries = read_log(logs / "SIM01-keyboard-trial1.sqlite")
    commands = [e.data for e in entries if e.kind == Kind.COMMAND]
    assert [c["action"] for c in commands] == ["navigate"] * 12
    assert {c["source"] for c in commands} == {"console"}
    # and in task III placebot2 was sent only after placebot1 had delivered, as seen
    third = [e for e in entries if e.task == "III"]
    delivered = next(
        e.seq for e in third if e.kind == Kind.ROBOT_EVENT and e.data["event"] == "delivered"
    )
    second = [e.seq for e in third if e.kind == Kind.COMMAND and e.data["target"] == "placebot2"]
    assert second and min(second) > delivered
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
    # Twelve orders of two clicks each (KLM and Fitts: about 3-4 s each), two questions to
    # the assistant and the glances at the screen
    assert 40 < ie < 150
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
    for name in ("subjective.png", "tlx_by_trial.png", "objective.png", "objective.svg"):
        assert (out / name).stat().st_size > 1000


def test_a_session_cut_mid_task_resumes_without_repeating_or_losing_anything(
    tmp_path: Path,
    lab: Lab,
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
        lab.broker_url,
        "--api",
        lab.api_url,
        "--simulate",
        "--speed-factor",
        str(SPEED),
        "--json",
    ]
    # Given a session interrupted (Ctrl-C) in task I, after its first click sequence
    original = SimulatedParticipant._click
    clicks: list[str | None] = []

    def interrupted(self: SimulatedParticipant, step: Any, *, hand_back: bool) -> None:
        clicks.append(self._task)
        if clicks.count("I") == 2:
            raise KeyboardInterrupt
        original(self, step, hand_back=hand_back)

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
    assert sent == ["navigate"] * 12
    assert all(body["success"] for body in summary["verdict"]["tasks"].values()), summary


def test_an_observed_keyboard_session_with_a_person_at_the_console(
    tmp_path: Path,
    lab: Lab,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
) -> None:
    import os
    import threading
    import time

    from vahr.domain import load_fleet
    from vahr.experiment.tasks import draw_plan

    logs = tmp_path / "logs"
    plan = draw_plan(load_fleet(), 21)
    path = logs / "P05-keyboard-trial2.sqlite"
    weather_zone = "A" if plan.weather == "sunny" else "C"
    one, two = plan.assignments["placebot1"], plan.assignments["placebot2"]
    # What the observer types in each task, each line once what it waits for (a robot
    # event in the task) is in the log: the participant's clicks, questions and puzzle parts
    Wait = tuple[str, str] | None
    typed: dict[str, list[tuple[Wait, str]]] = {
        "I": [
            (None, "p"),
            (None, "go placebot1 LOADING"),
            (None, "go placebot2 LOADING"),
            (("placebot1", "loaded"), f"go placebot1 {one}"),
            (("placebot2", "loaded"), f"go placebot2 {two}"),
            (None, "p 2"),
        ],
        "II": [
            (None, "q"),
            (None, "r"),
            (None, "q"),
            (None, "r"),
            (None, "go placebot1 LOADING"),
            (None, "go placebot2 LOADING"),
            (("placebot1", "loaded"), f"go placebot1 {weather_zone}"),
            (("placebot2", "loaded"), f"go placebot2 {weather_zone}"),
        ],
        "III": [
            (None, "k"),
            (None, "go placebot1 LOADING"),
            (("placebot1", "loaded"), "go placebot1 D"),
            (("placebot1", "delivered"), "w"),
            (None, "go placebot2 LOADING"),
            (("placebot2", "loaded"), "go placebot2 D"),
        ],
    }
    read_end, write_end = os.pipe()
    stop = threading.Event()

    def observer_types() -> None:
        for task in ("I", "II", "III"):
            for wait, line in typed[task]:
                while not stop.is_set():
                    entries = read_log(path) if path.exists() else []
                    started = [
                        e.seq for e in entries if e.kind == Kind.TASK_STARTED and e.task == task
                    ]
                    happened = {
                        (e.data.get("thing"), e.data.get("event"))
                        for e in entries
                        if started and e.seq > started[0] and e.kind == Kind.ROBOT_EVENT
                    }
                    if started and (wait is None or wait in happened):
                        break
                    time.sleep(0.05)
                os.write(write_end, f"{line}\n".encode())

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
                    lab.broker_url,
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
    ended = [e.data for e in entries if e.kind == Kind.INTERACTION_ENDED]
    clicks = [e for e in ended if e["channel"] == "click"]
    assert len(clicks) == 12 and all(c["commands"] for c in clicks)
    assert [e["channel"] for e in ended].count("watch") == 1
