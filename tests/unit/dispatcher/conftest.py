"""Fixtures for the dispatcher function's tests: moto's DynamoDB and iot-data, the table
as the CDK stack makes it (infra/constructs/task_table.py), and real-shaped events."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import boto3
import pytest
from moto import mock_aws

from dispatcher.task_table import TaskTable
from tests.support.dispatch_meter import REGION, TABLE
from tests.support.dynamodb_tables import create_task_table
from tests.support.shared_models import default_session

if TYPE_CHECKING:
    from collections.abc import Iterator


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
    for name in ("AWS_ENDPOINT_URL", "AWS_ENDPOINT_URL_IOT", "AWS_ENDPOINT_URL_IOT_DATA_PLANE"):
        monkeypatch.delenv(name, raising=False)


@pytest.fixture
def dynamodb(aws_credentials: None) -> Iterator[Any]:
    with mock_aws():
        default_session()
        client = boto3.client("dynamodb", region_name=REGION)
        create_task_table(client, TABLE)
        yield client


@pytest.fixture
def table(dynamodb: Any) -> TaskTable:
    return TaskTable(TABLE, client=dynamodb)
