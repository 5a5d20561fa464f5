"""The task table under moto's DynamoDB: the conditional writes that keep two robots from
taking one task and one robot from taking two, and the queue's order and lifecycle."""

from __future__ import annotations

import threading
from typing import TYPE_CHECKING, Any

import pytest

from dispatcher.errors import StoreError
from dispatcher.task_table import TaskTable
from tests.support.dispatch_meter import AtomicCalls
from vahr.dispatch import Task

if TYPE_CHECKING:
    from collections.abc import Callable

AT = "2026-11-26T23:00:00.000000Z"


def task(task_id: str, minute: int = 0, **fields: Any) -> Task:
    return Task(
        id=task_id,
        request="r1",
        kind="navigate",
        zone="C",
        created_at=f"2026-11-26T22:{minute:02d}:00.000000Z",
        **fields,
    )


def test_a_task_is_assigned_once_and_a_second_robot_is_refused(table: TaskTable) -> None:
    table.add(task("t1"))
    taken = table.assign("t1", "placebot1", at=AT)
    assert taken is not None
    assert (taken.status, taken.thing, taken.assigned_at, taken.version) == (
        "assigned",
        "placebot1",
        AT,
        2,
    )
    # Given the task is taken, when another robot claims it, nothing changes.
    assert table.assign("t1", "placebot2", at=AT) is None
    assert table.get("t1") == taken
    assert table.active() == [taken]
    assert table.pending() == []


def test_a_robot_holding_a_task_cannot_take_a_second(table: TaskTable) -> None:
    table.add(task("t1", 1))
    table.add(task("t2", 2))
    assert table.assign("t1", "placebot1", at=AT) is not None
    assert table.assign("t2", "placebot1", at=AT) is None
    assert [t.id for t in table.pending()] == ["t2"]
    assert table.get("t2") == task("t2", 2)


def test_two_robots_claiming_one_task_at_once_one_wins(table: TaskTable, dynamodb: Any) -> None:
    """Two dispatchers race for one task from two threads; exactly one claim holds."""
    table.add(task("t1"))
    first = TaskTable("vahr-tasks", client=AtomicCalls(dynamodb))
    second = TaskTable("vahr-tasks", client=AtomicCalls(dynamodb))
    start = threading.Barrier(2)
    won: dict[str, Task | None] = {}

    def claim(store: TaskTable, thing: str) -> Callable[[], None]:
        def run() -> None:
            start.wait(timeout=5)
            won[thing] = store.assign("t1", thing, at=AT)

        return run

    threads = [
        threading.Thread(target=claim(first, "placebot1")),
        threading.Thread(target=claim(second, "placebot2")),
    ]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join(timeout=10)
    winners = [thing for thing, taken in won.items() if taken is not None]
    assert len(winners) == 1
    stored = table.get("t1")
    assert stored is not None and stored.thing == winners[0] and stored.version == 2


def test_a_stale_claim_is_refused_by_its_version(table: TaskTable, dynamodb: Any) -> None:
    """A claim made on a read that another writer overtook is cancelled by the condition:
    the task was released meanwhile (version 3), so a write for version 1 must not land."""
    table.add(task("t1"))
    table.assign("t1", "placebot1", at=AT)
    table.release("t1")
    stale = table._task_item("open", task("t1", thing="placebot2", status="assigned"))
    with pytest.raises(Exception, match="TransactionCanceled"):
        dynamodb.transact_write_items(
            TransactItems=[
                {
                    "Put": {
                        "TableName": "vahr-tasks",
                        "Item": stale,
                        "ConditionExpression": "version = :seen",
                        "ExpressionAttributeValues": {":seen": {"N": "1"}},
                    }
                }
            ]
        )
    back = table.get("t1")
    assert back is not None and (back.status, back.thing, back.version) == ("queued", None, 3)


def test_release_puts_the_task_back_in_its_place_and_frees_the_robot(table: TaskTable) -> None:
    table.add(task("t1", 1))
    table.add(task("t2", 2))
    table.assign("t1", "placebot1", at=AT)
    released = table.release("t1")
    assert released is not None and released.status == "queued" and released.thing is None
    assert [t.id for t in table.pending()] == ["t1", "t2"]
    # The robot's claim went with it: it may take a task again.
    assert table.assign("t2", "placebot1", at=AT) is not None
    assert table.release("t1") is None  # not assigned


def test_finish_closes_the_task_and_frees_its_robot(table: TaskTable) -> None:
    table.add(task("t1", 1))
    table.add(task("t2", 2))
    table.assign("t1", "placebot1", at=AT)
    done = table.finish("t1", outcome="done")
    assert done is not None and (done.status, done.outcome) == ("done", "done")
    assert table.get("t1") == done  # kept, closed
    assert table.active() == []
    assert table.finish("t1", outcome="done") is None  # once only
    assert table.assign("t2", "placebot1", at=AT) is not None


def test_a_failed_task_ends_cancelled_with_its_outcome(table: TaskTable) -> None:
    table.add(task("t1"))
    table.assign("t1", "placebot1", at=AT)
    ended = table.finish("t1", outcome="preempted")
    assert ended is not None and (ended.status, ended.outcome) == ("cancelled", "preempted")


def test_cancel_returns_the_task_as_it_was_and_frees_its_robot(table: TaskTable) -> None:
    table.add(task("t1", 1))
    table.add(task("t2", 2))
    table.assign("t1", "placebot1", at=AT)
    before = table.cancel("t1")
    assert before is not None and (before.status, before.thing) == ("assigned", "placebot1")
    after = table.get("t1")
    assert after is not None and (after.status, after.outcome) == ("cancelled", "cancelled")
    assert table.cancel("t1") is None
    assert table.cancel("nope") is None
    queued = table.cancel("t2")
    assert queued is not None and queued.status == "queued"
    assert table.pending() == [] and table.active() == []
    # placebot1's claim is gone with its task.
    table.add(task("t3", 3))
    assert table.assign("t3", "placebot1", at=AT) is not None


def test_the_queue_is_first_come_first_served_across_pages(table: TaskTable) -> None:
    """Queried in pages of one: every open task is read, in created_at order."""
    table._page_limit = 1
    for minute, name in ((5, "late"), (1, "early"), (3, "middle")):
        table.add(task(name, minute))
    assert [t.id for t in table.pending()] == ["early", "middle", "late"]


def test_a_task_added_twice_is_refused(table: TaskTable) -> None:
    table.add(task("t1"))
    with pytest.raises(StoreError, match="t1 exists already"):
        table.add(task("t1"))


def test_a_missing_table_is_one_line(dynamodb: Any) -> None:
    with pytest.raises(StoreError, match="ResourceNotFoundException"):
        TaskTable("no-such-table", client=dynamodb).pending()


def test_offers_are_counted_beside_the_task_and_never_on_a_task_that_changed(
    table: TaskTable,
) -> None:
    # Given t1 assigned to placebot1 and t2 waiting
    table.add(task("t1"))
    table.add(task("t2", minute=1))
    taken = table.assign("t1", "placebot1", at=AT)
    assert taken is not None
    # When its command is sent again twice, then its robot is seen with it
    assert table.offered(taken, at="2026-11-26T22:05:00.000000Z")
    assert table.offered(taken, at="2026-11-26T22:06:00.000000Z")
    [offer], queued = table.offers()
    assert (offer.task, offer.offers, offer.offered_at, offer.acknowledged) == (
        taken, 2, "2026-11-26T22:06:00.000000Z", False,
    )  # fmt: skip
    assert [t.id for t in queued] == ["t2"] and table.holders() == {"placebot1"}
    assert table.acknowledged(taken)
    assert table.offers()[0][0].acknowledged
    # And once the task is cancelled, the version read is stale: nothing is counted
    table.cancel("t1")
    assert not table.offered(taken, at="2026-11-26T22:07:00.000000Z")
    assert not table.acknowledged(taken)
    assert table.offers() == ([], [table.get("t2")]) and table.holders() == set()
