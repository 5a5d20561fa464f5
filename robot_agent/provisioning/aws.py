"""Provision a robot in AWS IoT Core with boto3 (imported only here).

Creates the thing if it is missing; makes the key pair here, on the robot, and has AWS IoT
sign a certificate for it from a certificate signing request (the private key never leaves
the machine); attaches the fleet policy (made by the CDK stack), and the thing to the
certificate exclusively (`EXCLUSIVE_THING`: that certificate can never be attached to
another thing), and looks up the account's ATS data endpoint. A failure after the
certificate exists deactivates and deletes it again, so a failed run leaves no usable
orphan credentials behind. `retire_certificate` deactivates the certificate a new one
replaces (`robot-agent provision --force`).
"""

from __future__ import annotations

import logging
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import boto3
from botocore.exceptions import BotoCoreError, ClientError, NoCredentialsError, NoRegionError
from cryptography import x509
from cryptography.hazmat.primitives import hashes, serialization
from cryptography.hazmat.primitives.asymmetric import ec
from cryptography.x509.oid import NameOID

from vahr.errors import VahrError

log = logging.getLogger(__name__)

AMAZON_ROOT_CA_URL = "https://www.amazontrust.com/repository/AmazonRootCA1.pem"


@dataclass(frozen=True)
class AwsCredentials:
    thing: str
    certificate_arn: str
    certificate_id: str
    certificate_pem: str
    private_key: str
    endpoint: str
    thing_created: bool


def provision_thing(thing: str, *, policy: str, region: str | None = None) -> AwsCredentials:
    """Register `thing` and give it a certificate bound to `policy`; see the module docstring."""
    private_key, request = signing_request(thing)
    try:
        iot = boto3.client("iot", region_name=region)
        created = _ensure_thing(iot, thing)
        issued = iot.create_certificate_from_csr(
            certificateSigningRequest=request, setAsActive=True
        )
    except NoCredentialsError as err:
        raise VahrError("no AWS credentials found; configure a profile or AWS_* variables") from err
    except NoRegionError as err:
        raise VahrError("no AWS region set; pass --region or set AWS_REGION") from err
    except (ClientError, BotoCoreError) as err:
        raise VahrError(f"AWS IoT refused the request: {err}") from err
    arn, cert_id = issued["certificateArn"], issued["certificateId"]
    try:
        iot.attach_policy(policyName=policy, target=arn)
        iot.attach_thing_principal(
            thingName=thing, principal=arn, thingPrincipalType="EXCLUSIVE_THING"
        )
        endpoint = iot.describe_endpoint(endpointType="iot:Data-ATS")["endpointAddress"]
    except (ClientError, BotoCoreError) as err:
        _discard_certificate(iot, thing, policy, arn, cert_id)
        if _code(err) == "ResourceNotFoundException":
            raise VahrError(
                f"the IoT policy {policy!r} does not exist; deploy the CDK stack first "
                "or pass --policy NAME"
            ) from err
        raise VahrError(f"AWS IoT refused the request: {err}") from err
    return AwsCredentials(
        thing=thing,
        certificate_arn=arn,
        certificate_id=cert_id,
        certificate_pem=issued["certificatePem"],
        private_key=private_key,
        endpoint=endpoint,
        thing_created=created,
    )


def signing_request(thing: str) -> tuple[str, str]:
    """A new EC P-256 private key (PKCS8 PEM) and a CSR for it naming `thing`."""
    key = ec.generate_private_key(ec.SECP256R1())
    request = (
        x509.CertificateSigningRequestBuilder()
        .subject_name(x509.Name([x509.NameAttribute(NameOID.COMMON_NAME, thing)]))
        .sign(key, hashes.SHA256())
    )
    private = key.private_bytes(
        serialization.Encoding.PEM, serialization.PrivateFormat.PKCS8, serialization.NoEncryption()
    )
    return private.decode(), request.public_bytes(serialization.Encoding.PEM).decode()


def retire_certificate(
    thing: str, certificate_pem: str, *, region: str | None = None
) -> str | None:
    """Detach from `thing` and deactivate the certificate whose PEM is `certificate_pem` (the
    one a new certificate replaces); its id, or None when `thing` holds no such certificate."""
    wanted = _normalised(certificate_pem)
    try:
        iot = boto3.client("iot", region_name=region)
        for principal in _thing_principals(iot, thing):
            certificate_id = principal.rsplit("/", 1)[-1]
            if ":cert/" not in principal:
                continue
            description = iot.describe_certificate(certificateId=certificate_id)
            if _normalised(description["certificateDescription"]["certificatePem"]) != wanted:
                continue
            iot.detach_thing_principal(thingName=thing, principal=principal)
            iot.update_certificate(certificateId=certificate_id, newStatus="INACTIVE")
            return certificate_id
    except (ClientError, BotoCoreError) as err:
        raise VahrError(f"AWS IoT refused to retire the replaced certificate: {err}") from err
    return None


def _thing_principals(iot: Any, thing: str) -> list[str]:
    principals: list[str] = []
    pages = iot.get_paginator("list_thing_principals").paginate(thingName=thing)
    for page in pages:
        principals += page.get("principals", [])
    return principals


def _normalised(pem: str) -> str:
    return "".join(pem.split())


def _ensure_thing(iot: Any, thing: str) -> bool:
    try:
        iot.describe_thing(thingName=thing)
        return False
    except ClientError as err:
        if _code(err) != "ResourceNotFoundException":
            raise
    iot.create_thing(thingName=thing)
    return True


def _discard_certificate(iot: Any, thing: str, policy: str, arn: str, cert_id: str) -> None:
    # Best effort: each step may fail because the step it undoes never happened.
    for step in (
        lambda: iot.detach_thing_principal(thingName=thing, principal=arn),
        lambda: iot.detach_policy(policyName=policy, target=arn),
        lambda: iot.update_certificate(certificateId=cert_id, newStatus="INACTIVE"),
        lambda: iot.delete_certificate(certificateId=cert_id),
    ):
        try:
            step()
        except (ClientError, BotoCoreError) as err:
            log.debug("cleanup step failed: %s", err)


def _code(err: Exception) -> str:
    if isinstance(err, ClientError):
        return str(err.response.get("Error", {}).get("Code", ""))
    return ""


def amazon_root_ca(out_file: Path) -> Path | None:
    """Copy Amazon Root CA 1 from the local CA bundle (certifi), or None if it is absent."""
    try:
        import certifi
    except ImportError:
        return None
    bundle = Path(certifi.where()).read_text()
    marker = '# Label: "Amazon Root CA 1"'
    if marker not in bundle:
        return None
    block = bundle.split(marker, 1)[1]
    begin = block.index("-----BEGIN CERTIFICATE-----")
    end = block.index("-----END CERTIFICATE-----") + len("-----END CERTIFICATE-----")
    out_file.write_text(block[begin:end] + "\n")
    return out_file
