"""`/vahr/zones` on the local stack's data plane: zones closed and opened by a program are
in the audit trail (channel `api`), once: a sender that records its request itself (the
skill, the station, with the person who asked) says so and is not recorded twice."""

from __future__ import annotations

import json
from typing import TYPE_CHECKING

import pytest

from tests.support.fleets import SIX_ROBOTS
from vahr.dispatch import Dispatcher, RobotState
from vahr.domain import load_fleet
from vahr.local.dispatch_host import ZONES_PATH, ZonesApi
from vahr.local.task_store import SqliteTaskStore
from vahr.protocol.audit import RECORDED_BY_HEADER

if TYPE_CHECKING:
    from collections.abc import Iterator
    from pathlib import Path

    from vahr.protocol.audit import AuditEntry

BAKERY = load_fleet(SIX_ROBOTS)


class NoRobots:
    def available(self, *, zone: str | None = None) -> list[RobotState]:
        return []

    def state(self, thing: str) -> RobotState | None:
        return None


@pytest.fixture
def trail() -> list[AuditEntry]:
    return []


@pytest.fixture
def api(tmp_path: Path, trail: list[AuditEntry]) -> Iterator[ZonesApi]:
    store = SqliteTaskStore.in_state_dir(tmp_path)
    dispatcher = Dispatcher(
        fleet=BAKERY, store=store, candidates=NoRobots(), publish=lambda thing, command: None
    )
    yield ZonesApi(dispatcher, trail.append)
    store.close()


def close(api: ZonesApi, zone: str, headers: dict[str, str] | None = None) -> tuple[int, dict]:
    status, body, _ = api.respond(
        "POST", f"{ZONES_PATH}/{zone}", json.dumps({"closed": True}).encode(), headers
    )
    return status, json.loads(body)


def test_a_zone_a_program_closes_is_recorded_with_the_api_as_its_channel(
    api: ZonesApi, trail: list[AuditEntry]
) -> None:
    status, change = close(api, "OVEN")
    assert (status, change["closed"], change["changed"]) == (200, True, True)
    (record,) = trail
    assert (record.channel, record.intent, record.slots, record.outcome) == (
        "api", "close_zone", {"zone": "OVEN"}, "sent"
    )  # fmt: skip
    assert record.words == f"POST {ZONES_PATH}/OVEN"


def test_a_sender_that_recorded_its_request_is_not_recorded_twice(
    api: ZonesApi, trail: list[AuditEntry]
) -> None:
    status, _ = close(api, "OVEN", {RECORDED_BY_HEADER: "station"})
    assert status == 200 and trail == []


def test_an_unknown_zone_is_refused_in_one_line_and_recorded_as_failed(
    api: ZonesApi, trail: list[AuditEntry]
) -> None:
    status, body = close(api, "ATTIC")
    assert status == 400 and body["message"].startswith("there is no zone 'ATTIC'")
    (record,) = trail
    assert (record.outcome, record.reason) == ("failed", body["message"])
