"""The dispatcher rule's SQL (infra/constructs/dispatcher.py `freed_sql`) run on real-shaped
shadow `update/documents` messages with a small IoT SQL evaluator (iot_sql_eval.py): it
selects the updates that free a robot and passes the function what it reads.

moto does not evaluate topic rules at all, so what is checked here is the SQL's own logic
under AWS's documented semantics (Undefined for missing fields, three-valued AND/OR).
What only AWS can check: that the service accepts the SQL (cfn-lint checks only its
type), and the rule's delivery and error action.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest
from iot_sql_eval import UNDEFINED, parse, run, topic_matches

from infra.constructs.dispatcher import freed_sql
from vahr.protocol import topics

EVENTS = Path(__file__).resolve().parents[1] / "events"


def load_event(name: str) -> dict[str, Any]:
    loaded: dict[str, Any] = json.loads((EVENTS / f"{name}.json").read_text())
    return loaded


def documents_topic(thing: str) -> str:
    return topics.shadow(thing, "update/documents")


@pytest.mark.parametrize(
    "name",
    [
        "shadow_documents_task_done",  # navigating -> idle
        "shadow_documents_first_report",  # a new shadow, idle: no previous document
        "shadow_documents_reconnected",  # idle, connected again
        "shadow_documents_other_command_done",  # idle after a command given by name
    ],
)
def test_updates_that_free_a_robot_are_passed_on(name: str) -> None:
    message = load_event(name)
    passed = run(freed_sql(), documents_topic("placebot1"), message)
    assert passed == {
        "thing": "placebot1",
        "reported": message["current"]["state"]["reported"],
    }


@pytest.mark.parametrize(
    "name",
    [
        "shadow_documents_progress",  # still driving
        "shadow_documents_stuck",  # stuck is not free
        "shadow_documents_idle_again",  # idle before and after: nothing freed
    ],
)
def test_updates_that_free_nobody_are_not(name: str) -> None:
    assert run(freed_sql(), documents_topic("placebot1"), load_event(name)) is None


def test_the_handler_fixture_is_what_the_rule_passes_on() -> None:
    """tests/events/iot_rule_robot_freed.json, which the handler tests use, is exactly the
    rule's output for the finished task's document."""
    passed = run(
        freed_sql(), documents_topic("placebot1"), load_event("shadow_documents_task_done")
    )
    assert passed == load_event("iot_rule_robot_freed")


def test_only_classic_shadow_documents_are_read() -> None:
    message = load_event("shadow_documents_task_done")
    assert run(freed_sql(), topics.shadow("placebot1", "update/accepted"), message) is None
    # A named shadow's documents have two more topic levels: not matched by the filter.
    named = topics.shadow("placebot1", "update/documents", name="config")
    assert run(freed_sql(), named, message) is None
    assert run(freed_sql(), "vahr/robots/placebot1/events", message) is None


def test_a_shadow_without_a_status_is_not_a_robot_freed() -> None:
    # The experiment thing's shadow has no reported status: Undefined, not selected.
    experiment = {"current": {"state": {"reported": {"plan": {"trial": 1}}}}, "timestamp": 1}
    assert run(freed_sql(), documents_topic("vahr-experiment"), experiment) is None


def test_the_evaluator_keeps_aws_undefined_semantics() -> None:
    """Without the CASE, a first document (no `previous`) would be Undefined and lost: the
    reason freed_sql is written as it is."""
    naive = (
        "SELECT topic(3) AS thing FROM '$aws/things/+/shadow/update/documents' "
        "WHERE current.state.reported.status = 'idle' "
        "AND previous.state.reported.status <> current.state.reported.status"
    )
    first = load_event("shadow_documents_first_report")
    assert run(naive, documents_topic("placebot2"), first) is None
    assert run(freed_sql(), documents_topic("placebot2"), first) is not None
    assert topic_matches("$aws/things/+/shadow/update/documents", documents_topic("x"))
    rule = parse("SELECT a AS b FROM 't' WHERE NOT x = 1")
    assert rule.topic_filter == "t" and repr(UNDEFINED) == "Undefined"
