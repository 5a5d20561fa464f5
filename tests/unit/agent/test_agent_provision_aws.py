"""`robot-agent provision --aws` against moto's IoT: what exists in the account and on disk."""

from __future__ import annotations

import json
import stat
from typing import TYPE_CHECKING, Any

import boto3
import pytest
import yaml
from cryptography import x509
from cryptography.hazmat.primitives import serialization
from cryptography.x509.oid import NameOID
from moto import mock_aws

from robot_agent.cli import main
from tests.support.shared_models import default_session

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
        default_session()
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


# -- one identity per robot ----------------------------------------------------------------


def test_the_private_key_is_made_on_the_robot_and_aws_signs_its_csr(
    iot: object, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    # Given the AWS calls as botocore sends them (moto keeps no record of some parameters)
    calls = _recorded_calls(monkeypatch)
    out = tmp_path / "placebot1"
    # When the robot is provisioned
    assert main(["provision", "--thing", "placebot1", "--aws", "--out", str(out)]) == 0
    # Then the certificate came from a signing request, never from AWS-made keys
    operations = [name for name, _ in calls]
    assert "CreateCertificateFromCsr" in operations
    assert "CreateKeysAndCertificate" not in operations
    request = next(params for name, params in calls if name == "CreateCertificateFromCsr")
    csr = x509.load_pem_x509_csr(request["certificateSigningRequest"].encode())
    assert csr.subject.get_attributes_for_oid(NameOID.COMMON_NAME)[0].value == "placebot1"
    # And the key on disk is the one whose public half was sent to be signed; nothing sent
    # held it. (moto signs a key of its own instead of the request's, a moto gap, so the
    # certificate's key is not compared; its subject is the request's.)
    key = serialization.load_pem_private_key((out / "private.key").read_bytes(), None)
    assert _public(key.public_key()) == _public(csr.public_key())
    cert = x509.load_pem_x509_certificate((out / "cert.pem").read_bytes())
    assert cert.subject.get_attributes_for_oid(NameOID.COMMON_NAME)[0].value == "placebot1"
    sent = json.dumps([params for _, params in calls], default=str)
    assert "PRIVATE KEY" not in sent


def test_the_certificate_is_attached_to_its_thing_exclusively(
    iot: object, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    calls = _recorded_calls(monkeypatch)
    assert main(["provision", "--thing", "placebot1", "--aws", "--out", str(tmp_path / "p")]) == 0
    attach = [params for name, params in calls if name == "AttachThingPrincipal"]
    # moto 5.2.5 accepts thingPrincipalType but does not keep it (list_thing_principals_v2
    # gives no type back), so the request as sent is what is asserted, and moto's binding
    assert [(a["thingName"], a["thingPrincipalType"]) for a in attach] == [
        ("placebot1", "EXCLUSIVE_THING")
    ]
    client = boto3.client("iot", region_name=REGION)
    assert client.list_thing_principals(thingName="placebot1")["principals"] == [
        attach[0]["principal"]
    ]


def test_force_deactivates_and_detaches_the_certificate_it_replaces(
    iot: object, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "p1"
    client = boto3.client("iot", region_name=REGION)
    assert main(["provision", "--thing", "placebot1", "--aws", "--out", str(out)]) == 0
    (old_arn,) = client.list_thing_principals(thingName="placebot1")["principals"]
    old_id = old_arn.rsplit("/", 1)[-1]
    capsys.readouterr()
    # When the robot is provisioned again over its files
    code = main(["provision", "--thing", "placebot1", "--aws", "--out", str(out), "--force"])
    # Then the old certificate is inactive and no longer the thing's; the new one is
    assert code == 0
    assert f"replaced: certificate {old_id} (detached and deactivated)" in capsys.readouterr().out
    old = client.describe_certificate(certificateId=old_id)["certificateDescription"]
    assert old["status"] == "INACTIVE"
    (new_arn,) = client.list_thing_principals(thingName="placebot1")["principals"]
    assert new_arn != old_arn
    new_id = new_arn.rsplit("/", 1)[-1]
    new = client.describe_certificate(certificateId=new_id)["certificateDescription"]
    assert new["status"] == "ACTIVE"
    assert new["certificatePem"] == (out / "cert.pem").read_text()


@pytest.mark.parametrize("thing", ["vahr-station-lab", "vahr-service", "VAHR-recorder"])
def test_a_reserved_name_is_refused_as_a_thing_and_registers_nothing(
    iot: object, tmp_path: Path, capsys: pytest.CaptureFixture[str], thing: str
) -> None:
    code = main(["provision", "--thing", thing, "--aws", "--out", str(tmp_path / "x")])
    assert code == 2
    assert capsys.readouterr().err == (
        f"robot-agent provision: error: thing: {thing!r} is reserved: names starting with "
        "'vahr-' are the system's own identities (services, stations, recorders), never a "
        "robot's\n"
    )
    client = boto3.client("iot", region_name=REGION)
    assert client.list_things()["things"] == []
    assert client.list_certificates()["certificates"] == []


def test_a_reserved_name_is_refused_for_the_local_stack_too(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    code = main(
        ["provision", "--thing", "vahr-shadow-service", "--local", "--state-dir", str(tmp_path)]
    )
    assert code == 2
    assert "is reserved" in capsys.readouterr().err
    assert not (tmp_path / "pki").exists()


def _recorded_calls(monkeypatch: pytest.MonkeyPatch) -> list[tuple[str, dict[str, Any]]]:
    """Every IoT call's parameters as botocore is about to send them."""
    calls: list[tuple[str, dict[str, Any]]] = []
    session = boto3.session.Session()
    session.events.register(
        "provide-client-params.iot.*",
        lambda params, model, **_: calls.append((model.name, dict(params))),
    )
    monkeypatch.setattr(boto3, "DEFAULT_SESSION", session)
    return calls


def _public(key: Any) -> bytes:
    return bytes(
        key.public_bytes(
            serialization.Encoding.DER, serialization.PublicFormat.SubjectPublicKeyInfo
        )
    )
