"""Fixtures for the local stack's integration tests: one running stack per session and
boto3 pointed at its data plane."""

from __future__ import annotations

from typing import TYPE_CHECKING

import pytest

from vahr.plumbing.ports import free_port
from vahr.twin.stack import LocalStack, StackConfig

if TYPE_CHECKING:
    from collections.abc import Iterator


@pytest.fixture(scope="session")
def local_stack(tmp_path_factory: pytest.TempPathFactory) -> Iterator[LocalStack]:
    """Broker (mTLS + plaintext), shadow service and data plane on free loopback ports."""
    config = StackConfig(
        state_dir=tmp_path_factory.mktemp("stack"),
        mqtts_port=free_port(),
        mqtt_port=free_port(),
        api_port=free_port(),
    )
    with LocalStack(config) as stack:
        yield stack


@pytest.fixture
def aws_credentials(monkeypatch: pytest.MonkeyPatch) -> None:
    """Dummy credentials and region, so boto3 signs requests without a real account."""
    for name, value in {
        "AWS_ACCESS_KEY_ID": "testing",
        "AWS_SECRET_ACCESS_KEY": "testing",
        "AWS_SESSION_TOKEN": "testing",
        "AWS_DEFAULT_REGION": "us-east-1",
    }.items():
        monkeypatch.setenv(name, value)
    monkeypatch.delenv("AWS_PROFILE", raising=False)
