"""Fixtures for the dispatcher function's tests: moto's DynamoDB and iot-data, the table
as the CDK stack makes it (infra/constructs/task_table.py), and real-shaped events."""

from __future__ import annotations

import json
import threading
from pathlib import Path
from typing import TYPE_CHECKING, Any

import boto3
import pytest
from moto import mock_aws

from dispatcher.task_table import TaskTable

if TYPE_CHECKING:
    from collections.abc import Iterator

EVENTS = Path(__file__).resolve().parents[2] / "events"
REGION = "us-east-1"
TABLE = "vahr-tasks"


def load_event(name: str) -> dict[str, Any]:
    """A real-shaped JSON document from tests/events/ by name."""
    loaded: dict[str, Any] = json.loads((EVENTS / f"{name}.json").read_text())
    return loaded


# moto applies a DynamoDB transaction to a copy of its tables and, when a condition fails,
# puts the copy back: a transaction failing in one thread can undo one that succeeded in
# another meanwhile. DynamoDB itself runs each request atomically, so the race tests make
# each moto call atomic too; what they race is what the dispatchers race on AWS, the
# reads and conditional writes in between.
_MOTO = threading.Lock()


class AtomicCalls:
    """A boto3 client whose calls run one at a time, as DynamoDB runs each request."""

    def __init__(self, client: Any) -> None:
        self._client = client

    def __getattr__(self, name: str) -> Any:
        attribute = getattr(self._client, name)
        if not callable(attribute):
            return attribute

        def call(*args: Any, **kwargs: Any) -> Any:
            with _MOTO:
                return attribute(*args, **kwargs)

        return call


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
        client = boto3.client("dynamodb", region_name=REGION)
        # The key schema of infra/constructs/task_table.py.
        client.create_table(
            TableName=TABLE,
            KeySchema=[
                {"AttributeName": "section", "KeyType": "HASH"},
                {"AttributeName": "id", "KeyType": "RANGE"},
            ],
            AttributeDefinitions=[
                {"AttributeName": "section", "AttributeType": "S"},
                {"AttributeName": "id", "AttributeType": "S"},
            ],
            BillingMode="PAY_PER_REQUEST",
        )
        yield client


@pytest.fixture
def table(dynamodb: Any) -> TaskTable:
    return TaskTable(TABLE, client=dynamodb)
