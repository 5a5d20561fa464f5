"""The experiment's commands as a user meets them: the plan in the shadow, resuming, the
questionnaire, the report, and one-line errors."""

from __future__ import annotations

import json
from typing import TYPE_CHECKING

import boto3
import pytest
from moto import mock_aws

from tests.unit.experiment.test_report import generated_csv
from vahr.cli import main
from vahr.experiment.eventlog import Kind, read_log
from vahr.protocol import experiment_state_from_payload

if TYPE_CHECKING:
    from collections.abc import Iterator
    from pathlib import Path


@pytest.fixture
def iot_data(monkeypatch: pytest.MonkeyPatch) -> Iterator[object]:
    for name, value in {
        "AWS_ACCESS_KEY_ID": "testing",
        "AWS_SECRET_ACCESS_KEY": "testing",
        "AWS_DEFAULT_REGION": "us-east-1",
    }.items():
        monkeypatch.setenv(name, value)
    monkeypatch.delenv("AWS_ENDPOINT_URL_IOT_DATA_PLANE", raising=False)
    with mock_aws():
        boto3.client("iot").create_thing(thingName="vahr-experiment")
        yield boto3.client("iot-data")


def plan_only(logs: Path, *extra: str) -> list[str]:
    return [
        "experiment",
        "--participant",
        "P01",
        "--method",
        "vahr",
        "--trial",
        "1",
        "--log-dir",
        str(logs),
        "--plan-only",
        "--json",
        *extra,
    ]


def test_the_plan_is_written_to_the_experiment_shadow(
    tmp_path: Path, iot_data: object, capsys: pytest.CaptureFixture[str]
) -> None:
    # When a session is prepared with a seed
    assert main(plan_only(tmp_path, "--seed", "42")) == 0
    summary = json.loads(capsys.readouterr().out)
    # Then the experiment thing's reported state holds the weather and task I's zones
    shadow = iot_data.get_thing_shadow(thingName="vahr-experiment")  # type: ignore[attr-defined]
    state = experiment_state_from_payload(shadow["payload"].read())
    assert state.weather == summary["plan"]["weather"]
    assert state.assignments == summary["plan"]["assignments"]
    assert state.session == "P01-vahr-trial1"
    assert set(state.assignments) == {"placebot1", "placebot2"}
    assert len(set(state.assignments.values())) == 2
    assert set(state.assignments.values()) <= {"A", "B", "C", "D"}


def test_the_same_seed_draws_the_same_plan_and_seeds_differ(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    plans = []
    for index, seed in enumerate(["7", "7", "8", "9", "10", "11"]):
        assert main(plan_only(tmp_path / str(index), "--seed", seed, "--no-shadow")) == 0
        plans.append(json.loads(capsys.readouterr().out)["plan"])
    assert plans[0] == plans[1]
    drawn = {(json.dumps(p["assignments"], sort_keys=True), p["weather"]) for p in plans[2:]}
    assert len(drawn) > 1


def test_a_session_resumes_with_its_logged_plan(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(plan_only(tmp_path, "--seed", "3", "--no-shadow")) == 0
    first = json.loads(capsys.readouterr().out)
    # When the session is started again (after a crash) with another seed
    assert main(plan_only(tmp_path, "--seed", "4", "--no-shadow")) == 0
    again = json.loads(capsys.readouterr().out)
    # Then it resumes: same plan, and the log says so
    assert again["resumed"] is True
    assert again["plan"] == first["plan"]
    kinds = [e.kind for e in read_log(tmp_path / "P01-vahr-trial1.sqlite")]
    assert kinds == [Kind.SESSION_STARTED, Kind.SESSION_RESUMED]


def test_tlx_is_stored_with_the_session(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(plan_only(tmp_path, "--no-shadow")) == 0
    capsys.readouterr()
    answers = [
        "--mental",
        "1",
        "--physical",
        "11",
        "--temporal",
        "21",
        "--performance",
        "2",
        "--effort",
        "3",
        "--frustration",
        "4",
        "--confidence",
        "5",
        "--trust",
        "6",
    ]
    assert (
        main(
            [
                "tlx",
                "--participant",
                "P01",
                "--method",
                "vahr",
                "--trial",
                "1",
                "--log-dir",
                str(tmp_path),
                "--json",
                *answers,
            ]
        )
        == 0
    )
    stored = json.loads(capsys.readouterr().out)
    assert stored["percent"]["mental"] == 0 and stored["percent"]["physical"] == 50
    assert stored["percent"]["temporal"] == 100
    tlx = read_log(tmp_path / "P01-vahr-trial1.sqlite")[-1]
    assert (tlx.kind, tlx.data["levels"]["trust"]) == (Kind.TLX, 6)


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (
            ["tlx", "--participant", "P404", "--method", "vahr", "--trial", "1", "--mental", "3"],
            "no session log at",
        ),
        (["report", "--out", "OUT"], "give either a results CSV or --from-log DIR"),
        (["report", "missing.csv", "--out", "OUT"], "cannot read missing.csv"),
        (["report", "--from-log", "LOGS", "--out", "OUT"], "no finished sessions under"),
        (
            [
                "experiment",
                "--participant",
                "../x",
                "--method",
                "vahr",
                "--trial",
                "1",
                "--plan-only",
            ],
            "is not a valid id",
        ),
        (
            [
                "experiment",
                "--participant",
                "P1",
                "--method",
                "vahr",
                "--trial",
                "1",
                "--speed-factor",
                "5",
            ],
            "only for --simulate",
        ),
    ],
)
def test_bad_input_is_one_line_and_exit_2(
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
    argv: list[str],
    message: str,
) -> None:
    monkeypatch.chdir(tmp_path)
    (tmp_path / "LOGS").mkdir()
    assert main([*argv, "--log-dir", str(tmp_path)] if argv[0] == "tlx" else argv) == 2
    err = capsys.readouterr().err
    assert message in err
    assert len(err.strip().splitlines()) == 1


def test_tlx_without_a_terminal_names_the_missing_items(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    import io

    assert main(plan_only(tmp_path, "--no-shadow")) == 0
    monkeypatch.setattr("sys.stdin", io.StringIO(""))
    assert (
        main(
            [
                "tlx",
                "--participant",
                "P01",
                "--method",
                "vahr",
                "--trial",
                "1",
                "--log-dir",
                str(tmp_path),
                "--mental",
                "3",
            ]
        )
        == 2
    )
    assert "missing answers for --physical, --temporal" in capsys.readouterr().err


def test_report_from_a_csv(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    data = generated_csv(tmp_path / "results.csv", participants=4, trials=2)
    assert main(["report", str(data), "--out", str(tmp_path / "out"), "--json"]) == 0
    report = json.loads(capsys.readouterr().out)
    assert report["rows"] == 16
    assert report["objective"]["rad"]["p_value"] is not None
    assert (tmp_path / "out" / "report.md").is_file()


def test_no_aws_credentials_says_what_to_do(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    for name in (
        "AWS_ACCESS_KEY_ID",
        "AWS_SECRET_ACCESS_KEY",
        "AWS_SESSION_TOKEN",
        "AWS_PROFILE",
        "AWS_ENDPOINT_URL_IOT_DATA_PLANE",
    ):
        monkeypatch.delenv(name, raising=False)
    monkeypatch.setenv("AWS_SHARED_CREDENTIALS_FILE", str(tmp_path / "none"))
    monkeypatch.setenv("AWS_CONFIG_FILE", str(tmp_path / "none"))
    monkeypatch.setenv("AWS_EC2_METADATA_DISABLED", "true")
    assert main(plan_only(tmp_path)) == 2
    assert (
        capsys.readouterr()
        .err.strip()
        .endswith("no AWS credentials (give --api URL for the local stack, or --no-shadow)")
    )
