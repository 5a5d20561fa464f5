"""`python -m infra.skill_endpoint`: the deployed function ARN into skill.json's endpoint."""

from __future__ import annotations

import json
import shutil
import subprocess
import sys
from typing import TYPE_CHECKING

import pytest
from template_tools import REPO_ROOT

if TYPE_CHECKING:
    from pathlib import Path

ARN = "arn:aws:lambda:us-east-1:123456789012:function:Vahr-SkillFunction4ADF40E6-AbCdEf123456"


def run(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-m", "infra.skill_endpoint", *args],
        capture_output=True, text=True, timeout=60, cwd=REPO_ROOT,
    )  # fmt: skip


@pytest.fixture
def skill_json(tmp_path: Path) -> Path:
    """A copy of the repository's skill.json: the command edits it in place."""
    copy = tmp_path / "skill-package" / "skill.json"
    copy.parent.mkdir()
    shutil.copy(REPO_ROOT / "skill-package" / "skill.json", copy)
    return copy


def outputs_file(tmp_path: Path, outputs: object) -> Path:
    path = tmp_path / "cdk-outputs.json"
    path.write_text(json.dumps(outputs))
    return path


def test_the_function_arn_becomes_the_skill_endpoint_and_nothing_else_changes(
    tmp_path: Path, skill_json: Path
) -> None:
    # Given the outputs of `cdk deploy --outputs-file` and the skill package's manifest
    before = json.loads(skill_json.read_text())
    outputs = outputs_file(tmp_path, {"Vahr": {"SkillFunctionArn": ARN, "ThingNames": "a,b"}})
    # When the command runs
    result = run("--outputs", str(outputs), "--skill-json", str(skill_json))
    # Then it says what it wrote, and the endpoint is the function
    assert result.returncode == 0, result.stderr
    assert result.stdout.strip() == f"{skill_json}: endpoint {ARN}"
    after = json.loads(skill_json.read_text())
    assert after["manifest"]["apis"]["custom"]["endpoint"] == {"uri": ARN}
    # And everything else in the manifest is as it was
    del after["manifest"]["apis"]["custom"]["endpoint"]
    before["manifest"]["apis"]["custom"].pop("endpoint", None)
    assert after == before
    # And running it again changes nothing
    written = skill_json.read_bytes()
    assert run("--outputs", str(outputs), "--skill-json", str(skill_json)).returncode == 0
    assert skill_json.read_bytes() == written


def test_an_https_certificate_setting_is_dropped_for_a_lambda_endpoint(
    tmp_path: Path, skill_json: Path
) -> None:
    document = json.loads(skill_json.read_text())
    document["manifest"]["apis"]["custom"]["endpoint"] = {
        "uri": "https://example.org/alexa",
        "sslCertificateType": "Wildcard",
    }
    skill_json.write_text(json.dumps(document))
    outputs = outputs_file(tmp_path, {"Vahr": {"SkillFunctionArn": ARN}})
    assert run("--outputs", str(outputs), "--skill-json", str(skill_json)).returncode == 0
    endpoint = json.loads(skill_json.read_text())["manifest"]["apis"]["custom"]["endpoint"]
    assert endpoint == {"uri": ARN}


def test_the_stack_is_chosen_by_name_when_several_were_deployed(
    tmp_path: Path, skill_json: Path
) -> None:
    other = ARN.replace("Vahr-", "VahrLab-")
    outputs = outputs_file(
        tmp_path, {"Vahr": {"SkillFunctionArn": ARN}, "VahrLab": {"SkillFunctionArn": other}}
    )
    ambiguous = run("--outputs", str(outputs), "--skill-json", str(skill_json))
    assert ambiguous.returncode == 2
    assert ambiguous.stderr == (
        "error: several stacks have SkillFunctionArn (Vahr, VahrLab): pass --stack\n"
    )
    chosen = run("--outputs", str(outputs), "--skill-json", str(skill_json), "--stack", "VahrLab")
    assert chosen.returncode == 0
    assert (
        json.loads(skill_json.read_text())["manifest"]["apis"]["custom"]["endpoint"]["uri"] == other
    )


@pytest.mark.parametrize(
    ("outputs", "message"),
    [
        ({}, "error: no stack in the outputs file has SkillFunctionArn: was it deployed?"),
        ({"Vahr": {"SkillFunctionArn": "arn:aws:s3:::bucket"}},
         "error: Vahr.SkillFunctionArn is 'arn:aws:s3:::bucket', not a Lambda function ARN"),
        ({"Vahr": {"SkillFunctionArn": ARN}, "x": 1}, None),
        ([], "error: the outputs file is not a JSON object of stacks"),
    ],
)  # fmt: skip
def test_bad_outputs_are_refused_in_one_line_and_skill_json_is_untouched(
    tmp_path: Path, skill_json: Path, outputs: object, message: str | None
) -> None:
    before = skill_json.read_bytes()
    result = run("--outputs", str(outputs_file(tmp_path, outputs)), "--skill-json", str(skill_json))
    if message is None:
        assert result.returncode == 0
        return
    assert result.returncode == 2
    assert result.stderr == message + "\n"
    assert skill_json.read_bytes() == before


def test_missing_or_broken_files_are_named(tmp_path: Path, skill_json: Path) -> None:
    missing = run("--outputs", str(tmp_path / "nope.json"), "--skill-json", str(skill_json))
    assert missing.returncode == 2
    assert missing.stderr.startswith(
        f"error: cannot read the outputs file {tmp_path / 'nope.json'}"
    )
    broken = tmp_path / "broken.json"
    broken.write_text("{not json")
    result = run("--outputs", str(broken), "--skill-json", str(skill_json))
    assert result.returncode == 2
    assert result.stderr.startswith(f"error: the outputs file {broken} is not JSON (line 1")
    not_custom = tmp_path / "skill.json"
    not_custom.write_text(json.dumps({"manifest": {"apis": {"smartHome": {}}}}))
    outputs = outputs_file(tmp_path, {"Vahr": {"SkillFunctionArn": ARN}})
    result = run("--outputs", str(outputs), "--skill-json", str(not_custom))
    assert (
        result.stderr == "error: skill.json has no manifest.apis.custom: it is not a custom skill\n"
    )
    # A manifest of the wrong shape is named the same way, not a traceback.
    not_custom.write_text(json.dumps({"manifest": []}))
    result = run("--outputs", str(outputs), "--skill-json", str(not_custom))
    assert (
        result.stderr == "error: skill.json has no manifest.apis.custom: it is not a custom skill\n"
    )


def test_a_deployed_endpoint_does_not_count_as_drift_of_the_generated_package(
    tmp_path: Path,
) -> None:
    # Given a copy of the generated files, and the deployed ARN written into skill.json
    root = tmp_path / "checkout"
    shutil.copytree(REPO_ROOT / "skill-package", root / "skill-package")
    generated_fleet = REPO_ROOT / "lambda" / "skill" / "fleet.json"
    if generated_fleet.exists():
        (root / "lambda" / "skill").mkdir(parents=True)
        shutil.copy(generated_fleet, root / "lambda" / "skill" / "fleet.json")
    outputs = outputs_file(tmp_path, {"Vahr": {"SkillFunctionArn": ARN}})
    assert (
        run(
            "--outputs", str(outputs), "--skill-json", str(root / "skill-package" / "skill.json")
        ).returncode
        == 0
    )
    # When the skill model's drift check runs on it
    check = subprocess.run(
        [sys.executable, "-m", "vahr.skill_model", "--check", "--root", str(root)],
        capture_output=True, text=True, timeout=60, cwd=REPO_ROOT,
    )  # fmt: skip
    # Then the package is still up to date: `make test` passes after a deployment
    assert check.returncode == 0, check.stderr
