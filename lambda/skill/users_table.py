"""The users table on AWS (DynamoDB): one item per person, read with GetItem only.

Items: `{"id": S, "name": S, "role": S}`; the item with id `*` holds the role of everyone
not listed (`{"id": "*", "role": "viewer"}`). `vahr users import FILE --table NAME` writes
them from a users file (`write_people`, which the skill never calls: its role may only
read). A person read is kept for `CACHE_S`, so a warm function asks once per speaker and a
role changed in the table applies within that time.
"""

from __future__ import annotations

import time
from typing import TYPE_CHECKING, Any

import boto3
from botocore.config import Config
from botocore.exceptions import BotoCoreError, ClientError

from skill.errors import PeopleUnavailable
from vahr.domain.people import EVERYONE_ELSE, ROLES, Person

if TYPE_CHECKING:
    from collections.abc import Callable

    from vahr.domain.people import People, Role

CACHE_S = 30.0
WRITE_ATTEMPTS = 5
# The skill answers within Alexa's 8 s; a table slower than this is unavailable.
TIMEOUT_S = 2.0


class UsersTable:
    """`PeopleDirectory` over the DynamoDB users table."""

    def __init__(
        self,
        table_name: str,
        client: Any = None,
        *,
        clock: Callable[[], float] = time.monotonic,
    ) -> None:
        self.table_name = table_name
        self.client = client or boto3.client(
            "dynamodb",
            config=Config(
                connect_timeout=TIMEOUT_S, read_timeout=TIMEOUT_S, retries={"max_attempts": 2}
            ),
        )
        self._clock = clock
        self._cache: dict[str, tuple[float, dict[str, Any] | None]] = {}

    def _item(self, key: str) -> dict[str, Any] | None:
        cached = self._cache.get(key)
        if cached is not None and self._clock() - cached[0] < CACHE_S:
            return cached[1]
        try:
            answer = self.client.get_item(
                TableName=self.table_name, Key={"id": {"S": key}}, ConsistentRead=False
            )
        except (BotoCoreError, ClientError) as err:
            raise PeopleUnavailable(f"the users table cannot be read: {err}") from err
        item = answer.get("Item")
        self._cache[key] = (self._clock(), item)
        return item

    def person(self, person_id: str) -> Person:
        item = self._item(person_id)
        if item is not None:
            role = _role(item)
            name = item.get("name", {}).get("S")
            if role is not None and name:
                return Person(id=person_id, name=name, role=role)
        everyone = self._item(EVERYONE_ELSE)
        default = _role(everyone) if everyone is not None else None
        return Person(id=person_id, role=default or "viewer")


def _role(item: dict[str, Any]) -> Role | None:
    value = item.get("role", {}).get("S")
    return next((role for role in ROLES if role == value), None)


def write_people(
    people: People, table_name: str, client: Any = None, *, region: str | None = None
) -> int:
    """Put every person of a users file, and everyone else's role, into the table; remove
    people no longer in the file. Returns how many people the table holds."""
    client = client or boto3.client("dynamodb", region_name=region)
    wanted = {person.id for person in people.users} | {EVERYONE_ELSE}
    try:
        stale: list[str] = []
        for page in client.get_paginator("scan").paginate(
            TableName=table_name, ProjectionExpression="id"
        ):
            stale += [item["id"]["S"] for item in page.get("Items", [])]
        requests: list[dict[str, Any]] = [
            {
                "PutRequest": {
                    "Item": {"id": {"S": EVERYONE_ELSE}, "role": {"S": people.default_role}}
                }
            }
        ]
        for person in people.users:
            item = {
                "id": {"S": person.id},
                "name": {"S": str(person.name)},
                "role": {"S": person.role},
            }
            requests.append({"PutRequest": {"Item": item}})
        requests += [
            {"DeleteRequest": {"Key": {"id": {"S": key}}}} for key in stale if key not in wanted
        ]
        for start in range(0, len(requests), 25):  # BatchWriteItem's limit
            pending = {table_name: requests[start : start + 25]}
            for attempt in range(WRITE_ATTEMPTS):
                answer = client.batch_write_item(RequestItems=pending)
                pending = answer.get("UnprocessedItems") or {}
                if not pending:
                    break
                time.sleep(0.1 * 2**attempt)  # DynamoDB's advice for unprocessed items
            if pending:
                raise PeopleUnavailable(f"{table_name} kept refusing writes; try again")
    except (BotoCoreError, ClientError) as err:
        raise PeopleUnavailable(f"cannot write the users table {table_name}: {err}") from err
    return len(people.users)
