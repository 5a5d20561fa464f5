"""`robot-agent provision --aws` against moto's IoT: what exists in the account and on disk."""

from __future__ import annotations

import json
import stat
from typing import TYPE_CHECKING

import boto3
import pytest
import yaml
from moto import mock_aws

from robot_agent.cli import main

if TYPE_CHECKING:
    from collections.abc import Iterator
    from pathlib import Path

REGION = "eu-west-1"


@pytest.fixture
def aws_credentials(monkeypatch: pytest.MonkeyPatch) -> None:
    for name, value in {
        "AWS_ACCESS_KEY_ID": "testing",
        "AWS_SECRET_ACCESS_KEY": "testing",
        "AWS_SECURITY_TOKEN": "testing",
        "AWS_SESSION_TOKEN": "testing",
        "AWS_DEFAULT_REGION": REGION,
    }.items():
        monkeypatch.setenv(name, value)


@pytest.fixture
def iot(aws_credentials: None) -> Iterator[object]:
    with mock_aws():
        client = boto3.client("iot", region_name=REGION)
        client.create_policy(
            policyName="vahr-robot-policy",
            policyDocument=json.dumps(
                {
                    "Version": "2012-10-17",
                    "Statement": [{"Effect": "Allow", "Action": "iot:Connect", "Resource": "*"}],
                }
            ),
        )
        yield client


def test_provision_creates_the_thing_certificate_and_bindings_and_writes_private_files(
    iot: object, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "placebot1"
    # When
    code = main(["provision", "--thing", "placebot1", "--aws", "--out", str(out), "--json"])
    # Then
    assert code == 0
    printed = json.loads(capsys.readouterr().out)
    client = boto3.client("iot", region_name=REGION)
    assert client.describe_thing(thingName="placebot1")["thingName"] == "placebot1"
    principals = client.list_thing_principals(thingName="placebot1")["principals"]
    assert len(principals) == 1
    policies = client.list_attached_policies(target=principals[0])["policies"]
    assert [p["policyName"] for p in policies] == ["vahr-robot-policy"]
    cert_id = principals[0].split("/")[-1]
    description = client.describe_certificate(certificateId=cert_id)["certificateDescription"]
    assert description["status"] == "ACTIVE"
    assert (out / "cert.pem").read_text() == description["certificatePem"]
    assert "PRIVATE KEY" in (out / "private.key").read_text()
    for name in ("cert.pem", "private.key", "agent.yaml"):
        assert stat.S_IMODE((out / name).stat().st_mode) == 0o600, name
    assert stat.S_IMODE(out.stat().st_mode) == 0o700
    config = yaml.safe_load((out / "agent.yaml").read_text())
    endpoint = client.describe_endpoint(endpointType="iot:Data-ATS")["endpointAddress"]
    assert config["thing"] == "placebot1" and config["port"] == 8883
    assert config["endpoint"].endswith(".amazonaws.com") and endpoint.endswith(".amazonaws.com")
    assert config["cert"] == str((out / "cert.pem").resolve())
    assert printed["config"] == str(out / "agent.yaml")
    assert printed["ca"] == str(out / "AmazonRootCA1.pem")
    assert "BEGIN CERTIFICATE" in (out / "AmazonRootCA1.pem").read_text()


def test_an_existing_thing_is_reused(iot: object, tmp_path: Path) -> None:
    client = boto3.client("iot", region_name=REGION)
    client.create_thing(thingName="placebot2", attributePayload={"attributes": {"site": "lab"}})
    assert main(["provision", "--thing", "placebot2", "--aws", "--out", str(tmp_path / "p2")]) == 0
    thing = client.describe_thing(thingName="placebot2")
    assert thing["attributes"] == {"site": "lab"}


def test_a_missing_policy_is_one_line_and_leaves_no_active_certificate(
    iot: object, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    code = main(
        [
            "provision",
            "--thing",
            "placebot1",
            "--aws",
            "--policy",
            "nope",
            "--out",
            str(tmp_path / "x"),
        ]
    )
    assert code == 2
    assert capsys.readouterr().err.strip() == (
        "robot-agent provision: error: the IoT policy 'nope' does not exist; "
        "deploy the CDK stack first or pass --policy NAME"
    )
    client = boto3.client("iot", region_name=REGION)
    assert [c for c in client.list_certificates()["certificates"] if c["status"] == "ACTIVE"] == []
    assert not (tmp_path / "x" / "cert.pem").exists()


def test_existing_credentials_are_not_overwritten_without_force(
    iot: object, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "p1"
    assert main(["provision", "--thing", "placebot1", "--aws", "--out", str(out)]) == 0
    first = (out / "cert.pem").read_text()
    capsys.readouterr()
    assert main(["provision", "--thing", "placebot1", "--aws", "--out", str(out)]) == 2
    assert "pass --force to replace them" in capsys.readouterr().err
    assert (out / "cert.pem").read_text() == first
    assert main(["provision", "--thing", "placebot1", "--aws", "--out", str(out), "--force"]) == 0
    assert (out / "cert.pem").read_text() != first


def test_a_bad_thing_name_is_refused(
    iot: object, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(["provision", "--thing", "robot/1", "--aws", "--out", str(tmp_path)]) == 2
    assert "is not a valid thing name" in capsys.readouterr().err


def test_the_plain_output_names_every_file_and_a_given_ca_is_used(
    iot: object, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    ca = tmp_path / "my-ca.pem"
    ca.write_text("-----BEGIN CERTIFICATE-----\nMIIB\n-----END CERTIFICATE-----\n")
    out = tmp_path / "p1"
    assert (
        main(
            ["provision", "--thing", "placebot1", "--aws", "--out", str(out), "--ca-file", str(ca)]
        )
        == 0
    )
    lines = capsys.readouterr().out.splitlines()
    assert [line.split(":", 1)[0] for line in lines] == ["cert", "key", "ca", "config", "endpoint"]
    assert lines[2] == f"ca:     {out / 'ca.pem'}"
    assert (out / "ca.pem").read_text() == ca.read_text()
    assert yaml.safe_load((out / "agent.yaml").read_text())["ca"] == str((out / "ca.pem").resolve())


def test_an_unreadable_ca_file_is_one_line_and_registers_nothing(
    iot: object, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # Given a --ca-file that does not exist
    missing = tmp_path / "no-such-ca.pem"
    # When the robot is provisioned with it
    code = main(
        [
            "provision",
            "--thing",
            "placebot1",
            "--aws",
            "--ca-file",
            str(missing),
            "--out",
            str(tmp_path / "x"),
        ]
    )
    # Then it is a one-line error, and no certificate was registered or written
    assert code == 2
    assert capsys.readouterr().err.strip() == (
        f"robot-agent provision: error: --ca-file {missing}: No such file or directory"
    )
    client = boto3.client("iot", region_name=REGION)
    assert client.list_certificates()["certificates"] == []
    assert not (tmp_path / "x" / "cert.pem").exists()


def test_an_out_dir_that_cannot_be_made_is_one_line_and_registers_nothing(
    iot: object, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # Given --out naming a file, not a directory
    taken = tmp_path / "taken"
    taken.write_text("")
    # When the robot is provisioned there
    code = main(["provision", "--thing", "placebot1", "--aws", "--out", str(taken)])
    # Then it is a one-line error before anything is registered
    assert code == 2
    assert capsys.readouterr().err.strip() == (
        f"robot-agent provision: error: cannot make the directory {taken}: File exists"
    )
    client = boto3.client("iot", region_name=REGION)
    assert client.list_certificates()["certificates"] == []


def test_a_port_out_of_range_is_one_line_and_registers_nothing(
    iot: object, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    code = main(
        ["provision", "--thing", "placebot1", "--aws", "--port", "0", "--out", str(tmp_path / "x")]
    )
    assert code == 2
    assert capsys.readouterr().err.strip() == (
        "robot-agent provision: error: --port 0: expected a TCP port (1-65535)"
    )
    client = boto3.client("iot", region_name=REGION)
    assert client.list_certificates()["certificates"] == []
