"""The task queue in DynamoDB: `vahr.dispatch.TaskStore` with conditional writes.

One table, keyed by `section` (partition) and `id` (sort):

| section | id | holds |
| --- | --- | --- |
| `open` | task id | a queued or assigned task: `task` (its JSON), `status`, `version` |
| `closed` | task id | a done or cancelled task, kept until `expires_at` (the table's TTL) |
| `robot` | thing | the robot's claim on its one assigned task: `task_id` |
| `zone` | zone id | a zone closed at run time, since `closed_at` |
| `charger` | zone id | the charger's hold by its one assigned `charge` task: `task_id` |
| `service` | thing | a robot out of service, since `since` |

An assigned task's item also keeps how its command fared, beside the task: `offers` (how
often the schedule sent it again), `offered_at` (when last) and `acknowledged` (its robot
was seen to have it). Rewriting the task (released, assigned anew) starts them afresh.

Every open task lives in one partition, so the queue is one strongly consistent Query
(a fleet's queue is tens of tasks, far below a partition's 3,000 reads a second), and a
finished task leaves that partition, so the Query never reads the history.

`assign` is one transaction of two conditional writes: the task's item is rewritten only
if its `version` is the one read and it is still `queued`, and the robot's claim is
created only if the robot has none. Either condition failing cancels both: two robots
never take one task, one robot never takes two. A `charge` task's `assign` adds a third:
the charger's hold, created only if the charger has none, so two robots never take one
charger, whichever invocations race for it; releasing or closing the task drops the hold
in the same transaction. Every other change is conditional on the
version read too, and is retried on a lost race a bounded number of times.
"""

from __future__ import annotations

import time
from typing import TYPE_CHECKING, Any

import boto3
import msgspec
from botocore.config import Config
from botocore.exceptions import BotoCoreError, ClientError

from dispatcher.errors import StoreError
from vahr.dispatch import Task

if TYPE_CHECKING:
    from vahr.dispatch import Outcome

CLIENT_CONFIG = Config(
    connect_timeout=2.0, read_timeout=3.0, retries={"mode": "standard", "total_max_attempts": 3}
)
OPEN, CLOSED, ROBOT, ZONE = "open", "closed", "robot", "zone"
CHARGER, SERVICE = "charger", "service"
# A change that lost a race to another writer reads the task again and decides anew; a
# task is written by a handful of invocations at most, so a few rounds settle it.
ATTEMPTS = 4
_LOST_RACE = ("ConditionalCheckFailed", "TransactionConflict")


class _Conflict(Exception):
    """A conditional write found the item changed since it was read."""


class Offer(msgspec.Struct, frozen=True, kw_only=True):
    """An assigned task and how its command fared: sent again `offers` times (the last at
    `offered_at`), and whether its robot was seen to have it (`acknowledged`)."""

    task: Task
    offers: int = 0
    offered_at: str | None = None
    acknowledged: bool = False


class TaskTable:
    """The dispatcher's TaskStore on one DynamoDB table (see the module docstring)."""

    def __init__(self, table: str, *, closed_task_days: int = 30, client: Any = None) -> None:
        self._table = table
        self._keep_closed_s = closed_task_days * 86_400
        self._client = client or boto3.client("dynamodb", config=CLIENT_CONFIG)
        self._encoder = msgspec.json.Encoder()
        self._decoder = msgspec.json.Decoder(Task)
        # DynamoDB's own page limit (1 MB) unless set; tests set it to read in small pages.
        self._page_limit: int | None = None

    # --- TaskStore ------------------------------------------------------------------------

    def add(self, task: Task) -> None:
        try:
            self._client.put_item(
                TableName=self._table,
                Item=self._task_item(OPEN, task),
                ConditionExpression="attribute_not_exists(id)",
            )
        except ClientError as err:
            if _code(err) == "ConditionalCheckFailedException":
                raise StoreError(f"task {task.id} exists already") from err
            raise StoreError(f"cannot add task {task.id}: {_message(err)}") from err
        except BotoCoreError as err:
            raise StoreError(f"cannot add task {task.id}: {err}") from err

    def assign(self, task_id: str, thing: str, *, at: str) -> Task | None:
        task = self._open(task_id)
        if task is None or task.status != "queued":
            return None
        taken = task.assigned(thing, at=at)
        writes = [
            self._rewrite(taken, seen=task, status="queued"),
            self._claim(ROBOT, thing, task_id),
        ]
        if task.kind == "charge":
            writes.append(self._claim(CHARGER, task.zone, task_id))
        try:
            self._transact(*writes)
        except _Conflict:
            return None
        return taken

    def release(self, task_id: str) -> Task | None:
        for _ in range(ATTEMPTS):
            task = self._open(task_id)
            if task is None or task.status != "assigned" or task.thing is None:
                return None
            back = task.released()
            try:
                self._transact(self._rewrite(back, seen=task), *self._drop_claims(task))
            except _Conflict:
                continue
            return back
        return None

    def finish(self, task_id: str, *, outcome: Outcome) -> Task | None:
        for _ in range(ATTEMPTS):
            task = self._open(task_id)
            if task is None or task.status != "assigned" or task.thing is None:
                return None
            ended = task.finished(outcome)
            try:
                self._close(task, ended)
            except _Conflict:
                continue
            return ended
        return None

    def cancel(self, task_id: str) -> Task | None:
        for _ in range(ATTEMPTS):
            task = self._open(task_id)
            if task is None or not task.is_open:
                return None
            ended = task.cancelled()
            try:
                self._close(task, ended)
            except _Conflict:
                continue
            return task
        return None

    def get(self, task_id: str) -> Task | None:
        return self._open(task_id) or self._read(CLOSED, task_id)

    def pending(self) -> list[Task]:
        queued = [task for task in self._all_open() if task.status == "queued"]
        return sorted(queued, key=lambda task: task.order_key)

    def active(self) -> list[Task]:
        assigned = [task for task in self._all_open() if task.status == "assigned"]
        return sorted(assigned, key=lambda task: (task.assigned_at or "", task.id))

    # --- beyond the TaskStore: what the schedule needs to offer a task again ---------------

    def offers(self) -> tuple[list[Offer], list[Task]]:
        """Every assigned task with how its command fared (oldest first), and the queue:
        one read of the open tasks."""
        assigned: list[Offer] = []
        queued: list[Task] = []
        for item in self._open_items():
            task = self._decode(item)
            if task.status == "queued":
                queued.append(task)
                continue
            assigned.append(
                Offer(
                    task=task,
                    offers=int(item.get("offers", {}).get("N", "0")),
                    offered_at=item.get("offered_at", {}).get("S"),
                    acknowledged=item.get("acknowledged", {}).get("BOOL", False),
                )
            )
        assigned.sort(key=lambda offer: (offer.task.assigned_at or "", offer.task.id))
        return assigned, sorted(queued, key=lambda task: task.order_key)

    def offered(self, task: Task, *, at: str) -> bool:
        """Count one more sending of `task`'s command, at `at`; False when the task changed
        meanwhile (it ended, or went back to the queue)."""
        return self._mark(
            task,
            "SET offers = if_not_exists(offers, :zero) + :one, offered_at = :at",
            {":zero": {"N": "0"}, ":one": {"N": "1"}, ":at": {"S": at}},
        )

    def acknowledged(self, task: Task) -> bool:
        """Record that `task`'s robot has its command: it is never sent again."""
        return self._mark(task, "SET acknowledged = :yes", {":yes": {"BOOL": True}})

    def holders(self) -> set[str]:
        """The robots holding a task now (their claims)."""
        return set(self._keys(ROBOT, "the robots' claims"))

    def chargers_held(self) -> dict[str, str]:
        """Each charger held now, with the id of the charge task holding it."""
        return {
            item["id"]["S"]: item.get("task_id", {}).get("S", "")
            for item in self._section(CHARGER, "the chargers' holds")
        }

    # --- robots out of service ------------------------------------------------------------

    def set_in_service(self, thing: str, in_service: bool, *, at: str) -> bool:
        """Record `thing` in service or out of it (since `at`); False when it already was.
        One conditional write: two invocations changing it at once change it once."""
        key = {"section": {"S": SERVICE}, "id": {"S": thing}}
        try:
            if in_service:
                answer = self._client.delete_item(
                    TableName=self._table, Key=key, ReturnValues="ALL_OLD"
                )
                return "Attributes" in answer
            self._client.put_item(
                TableName=self._table,
                Item={**key, "since": {"S": at}},
                ConditionExpression="attribute_not_exists(id)",
            )
        except ClientError as err:
            if _code(err) == "ConditionalCheckFailedException":
                return False
            raise StoreError(f"cannot record {thing}'s service: {_message(err)}") from err
        except BotoCoreError as err:
            raise StoreError(f"cannot record {thing}'s service: {err}") from err
        return True

    def out_of_service(self) -> list[str]:
        """The robots out of service now, sorted."""
        return sorted(self._keys(SERVICE, "the robots out of service"))

    def close_zone(self, zone: str, *, at: str) -> bool:
        try:
            self._client.put_item(
                TableName=self._table,
                Item={"section": {"S": ZONE}, "id": {"S": zone}, "closed_at": {"S": at}},
                ConditionExpression="attribute_not_exists(id)",
            )
        except ClientError as err:
            if _code(err) == "ConditionalCheckFailedException":
                return False
            raise StoreError(f"cannot close zone {zone}: {_message(err)}") from err
        except BotoCoreError as err:
            raise StoreError(f"cannot close zone {zone}: {err}") from err
        return True

    def open_zone(self, zone: str) -> bool:
        try:
            answer = self._client.delete_item(
                TableName=self._table,
                Key={"section": {"S": ZONE}, "id": {"S": zone}},
                ReturnValues="ALL_OLD",
            )
        except (ClientError, BotoCoreError) as err:
            raise StoreError(f"cannot open zone {zone}: {_message(err)}") from err
        return "Attributes" in answer

    def closed_zones(self) -> list[str]:
        return sorted(self._keys(ZONE, "the closed zones"))

    def _keys(self, section: str, what: str) -> list[str]:
        return [item["id"]["S"] for item in self._section(section, what)]

    def _section(self, section: str, what: str) -> list[dict[str, Any]]:
        """Every item of one small section (claims, holds, zones, robots out of service),
        strongly consistent, page after page."""
        query: dict[str, Any] = {
            "TableName": self._table,
            "KeyConditionExpression": "#section = :section",
            "ExpressionAttributeNames": {"#section": "section"},
            "ExpressionAttributeValues": {":section": {"S": section}},
            "ConsistentRead": True,
        }
        items: list[dict[str, Any]] = []
        while True:
            try:
                page = self._client.query(**query)
            except (ClientError, BotoCoreError) as err:
                raise StoreError(f"cannot read {what}: {_message(err)}") from err
            items.extend(page.get("Items", []))
            if "LastEvaluatedKey" not in page:
                return items
            query["ExclusiveStartKey"] = page["LastEvaluatedKey"]

    # --- inside ---------------------------------------------------------------------------

    def _task_item(self, section: str, task: Task) -> dict[str, Any]:
        item: dict[str, Any] = {
            "section": {"S": section},
            "id": {"S": task.id},
            "task": {"S": self._encoder.encode(task).decode()},
            "status": {"S": task.status},
            "version": {"N": str(task.version)},
        }
        if section == CLOSED:
            item["expires_at"] = {"N": str(int(time.time()) + self._keep_closed_s)}
        return item

    def _rewrite(self, task: Task, *, seen: Task, status: str | None = None) -> dict[str, Any]:
        """Put the open item, only over the version read (and the status, when given)."""
        condition = "version = :seen"
        values: dict[str, Any] = {":seen": {"N": str(seen.version)}}
        if status is not None:
            condition += " AND #status = :status"
            values[":status"] = {"S": status}
        put: dict[str, Any] = {
            "TableName": self._table,
            "Item": self._task_item(OPEN, task),
            "ConditionExpression": condition,
            "ExpressionAttributeValues": values,
        }
        if status is not None:
            put["ExpressionAttributeNames"] = {"#status": "status"}
        return {"Put": put}

    def _claim(self, section: str, key: str, task_id: str) -> dict[str, Any]:
        """Create a robot's or a charger's hold by `task_id`, only if it has none."""
        return {
            "Put": {
                "TableName": self._table,
                "Item": {"section": {"S": section}, "id": {"S": key}, "task_id": {"S": task_id}},
                "ConditionExpression": "attribute_not_exists(id)",
            }
        }

    def _drop_claims(self, task: Task) -> list[dict[str, Any]]:
        """Drop the holds an assigned task has: its robot's and, a charge task, its
        charger's."""
        drops = []
        if task.thing is not None:
            drops.append(self._drop_claim(ROBOT, task.thing, task.id))
        if task.kind == "charge":
            # A charge task assigned before chargers were held has no hold to drop.
            drops.append(self._drop_claim(CHARGER, task.zone, task.id, missing_ok=True))
        return drops

    def _drop_claim(
        self, section: str, key: str, task_id: str, *, missing_ok: bool = False
    ) -> dict[str, Any]:
        condition = "task_id = :task"
        if missing_ok:
            condition = f"attribute_not_exists(id) OR {condition}"
        return {
            "Delete": {
                "TableName": self._table,
                "Key": {"section": {"S": section}, "id": {"S": key}},
                "ConditionExpression": condition,
                "ExpressionAttributeValues": {":task": {"S": task_id}},
            }
        }

    def _close(self, before: Task, ended: Task) -> None:
        """Move a task from the open partition to the closed one (and free its robot)."""
        writes = [
            {
                "Delete": {
                    "TableName": self._table,
                    "Key": {"section": {"S": OPEN}, "id": {"S": before.id}},
                    "ConditionExpression": "version = :seen",
                    "ExpressionAttributeValues": {":seen": {"N": str(before.version)}},
                }
            },
            {"Put": {"TableName": self._table, "Item": self._task_item(CLOSED, ended)}},
        ]
        if before.status == "assigned":
            writes.extend(self._drop_claims(before))
        self._transact(*writes)

    def _transact(self, *writes: dict[str, Any]) -> None:
        try:
            self._client.transact_write_items(TransactItems=list(writes))
        except ClientError as err:
            if _code(err) == "TransactionCanceledException":
                reasons = err.response.get("CancellationReasons") or []
                codes = {reason.get("Code") for reason in reasons}
                if not reasons or codes & set(_LOST_RACE):
                    raise _Conflict from err
            if _code(err) == "TransactionConflictException":
                raise _Conflict from err
            raise StoreError(f"cannot write the task table: {_message(err)}") from err
        except BotoCoreError as err:
            raise StoreError(f"cannot write the task table: {err}") from err

    def _mark(self, task: Task, update: str, values: dict[str, Any]) -> bool:
        """Update an assigned task's open item beside its JSON, over the version read."""
        try:
            self._client.update_item(
                TableName=self._table,
                Key={"section": {"S": OPEN}, "id": {"S": task.id}},
                UpdateExpression=update,
                ConditionExpression="version = :seen AND #status = :assigned",
                ExpressionAttributeNames={"#status": "status"},
                ExpressionAttributeValues={
                    **values,
                    ":seen": {"N": str(task.version)},
                    ":assigned": {"S": "assigned"},
                },
            )
        except ClientError as err:
            if _code(err) == "ConditionalCheckFailedException":
                return False
            raise StoreError(f"cannot update task {task.id}: {_message(err)}") from err
        except BotoCoreError as err:
            raise StoreError(f"cannot update task {task.id}: {err}") from err
        return True

    def _open(self, task_id: str) -> Task | None:
        return self._read(OPEN, task_id)

    def _read(self, section: str, task_id: str) -> Task | None:
        try:
            item = self._client.get_item(
                TableName=self._table,
                Key={"section": {"S": section}, "id": {"S": task_id}},
                ConsistentRead=True,
            ).get("Item")
        except (ClientError, BotoCoreError) as err:
            raise StoreError(f"cannot read task {task_id}: {_message(err)}") from err
        return None if item is None else self._decode(item)

    def _all_open(self) -> list[Task]:
        return [self._decode(item) for item in self._open_items()]

    def _open_items(self) -> list[dict[str, Any]]:
        items: list[dict[str, Any]] = []
        query: dict[str, Any] = {
            "TableName": self._table,
            "KeyConditionExpression": "#section = :open",
            "ExpressionAttributeNames": {"#section": "section"},
            "ExpressionAttributeValues": {":open": {"S": OPEN}},
            "ConsistentRead": True,
        }
        if self._page_limit is not None:
            query["Limit"] = self._page_limit
        while True:
            try:
                page = self._client.query(**query)
            except (ClientError, BotoCoreError) as err:
                raise StoreError(f"cannot read the task queue: {_message(err)}") from err
            items.extend(page.get("Items", []))
            if "LastEvaluatedKey" not in page:
                return items
            query["ExclusiveStartKey"] = page["LastEvaluatedKey"]

    def _decode(self, item: dict[str, Any]) -> Task:
        try:
            task: Task = self._decoder.decode(item["task"]["S"])
        except (KeyError, msgspec.DecodeError) as err:
            raise StoreError(f"task {item.get('id', {}).get('S')} is unreadable: {err}") from err
        return task


def _code(err: ClientError) -> str:
    return str(err.response.get("Error", {}).get("Code", ""))


def _message(err: Exception) -> str:
    if isinstance(err, ClientError):
        return f"{_code(err)}: {err.response.get('Error', {}).get('Message', '')}"
    return str(err)
