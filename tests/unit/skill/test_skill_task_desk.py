"""The skill's two TaskDesk adapters against the real other side.

- `HttpTaskDesk` over real HTTP on 127.0.0.1 to the local host's `/vahr/tasks` routes
  (`vahr.local.dispatch_host.TasksApi`, the object the data plane serves);
- `LambdaTaskDesk` against the dispatcher function's own handler (`dispatcher.app.handle`),
  called in-process by a client with boto3's `invoke` shape, since no Lambda runtime runs
  here: the request and answer shapes are the function's.

Both sides run the same dispatch core on a SQLite store, so the tests read what a person
would hear about: who took a task, its place in line, a refusal's one line.
"""

from __future__ import annotations

import io
import json
import threading
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from typing import TYPE_CHECKING, Any

import pytest

from skill.task_desk import HttpTaskDesk, LambdaTaskDesk, TaskDesk, TaskRefused
from tests.support.fleets import SIX_ROBOTS
from vahr.dispatch import Dispatcher, Order, RobotState
from vahr.domain import load_fleet
from vahr.local.dispatch_host import TasksApi
from vahr.local.task_store import SqliteTaskStore

if TYPE_CHECKING:
    from collections.abc import Iterator
    from pathlib import Path

    from vahr.protocol import Command

BAKERY = load_fleet(SIX_ROBOTS)


class IdleBirds:
    """Every robot idle at its start."""

    def available(self, *, zone: str | None = None) -> list[RobotState]:
        return [
            RobotState(thing=robot.thing, status="idle", pose=robot.start)
            for robot in BAKERY.robots
            if zone is None
        ]

    def state(self, thing: str) -> RobotState | None:
        return None


@pytest.fixture
def dispatcher(tmp_path: Path) -> Iterator[Dispatcher]:
    store = SqliteTaskStore.in_state_dir(tmp_path)
    sent: list[tuple[str, Command]] = []
    yield Dispatcher(
        fleet=BAKERY, store=store, candidates=IdleBirds(), publish=lambda t, c: sent.append((t, c))
    )
    store.close()


@pytest.fixture
def http_desk(dispatcher: Dispatcher) -> Iterator[HttpTaskDesk]:
    api = TasksApi(dispatcher)

    class Handler(BaseHTTPRequestHandler):
        def _serve(self) -> None:
            body = self.rfile.read(int(self.headers.get("Content-Length") or 0))
            status, payload, _ = api.respond(self.command, self.path, body)
            self.send_response(status)
            self.send_header("Content-Length", str(len(payload)))
            self.end_headers()
            self.wfile.write(payload)

        do_GET = do_POST = do_DELETE = _serve  # noqa: N815

        def log_message(self, *args: object) -> None:
            pass

    server = ThreadingHTTPServer(("127.0.0.1", 0), Handler)
    thread = threading.Thread(target=server.serve_forever, daemon=True)
    thread.start()
    try:
        yield HttpTaskDesk(f"http://127.0.0.1:{server.server_address[1]}")
    finally:
        server.shutdown()
        server.server_close()
        thread.join(timeout=5)


class InProcessLambda:
    """boto3's lambda client's `invoke`, answered by the dispatcher function's handler."""

    def __init__(self, dispatcher: Dispatcher) -> None:
        from dispatcher.app import handle

        self.handle = handle
        self.dispatcher = dispatcher
        self.invoked: list[dict[str, Any]] = []

    def invoke(self, *, FunctionName: str, InvocationType: str, Payload: bytes) -> dict[str, Any]:  # noqa: N803
        assert InvocationType == "RequestResponse"
        event = json.loads(Payload)
        self.invoked.append(event)
        answer = self.handle(event, self.dispatcher)
        return {"StatusCode": 200, "Payload": io.BytesIO(json.dumps(answer).encode())}


@pytest.fixture(params=["http", "lambda"])
def desk(request: pytest.FixtureRequest, dispatcher: Dispatcher) -> TaskDesk:
    if request.param == "http":
        return request.getfixturevalue("http_desk")  # type: ignore[no-any-return]
    return LambdaTaskDesk("vahr-dispatcher", client=InProcessLambda(dispatcher))


def test_an_order_is_taken_queued_listed_and_cancelled_through_either_desk(desk: TaskDesk) -> None:
    first = desk.submit(Order(kind="deliver", zone="OVEN"))
    assert [task.thing for task in first.assigned] == ["osprey"]
    rest = desk.submit(Order(zone="SHOP", count=6))
    assert len(rest.assigned) == 5 and rest.positions == [1]
    tasks = desk.tasks()
    assert [task.status for task in tasks] == ["assigned"] * 6 + ["queued"]
    cancelled = desk.cancel(rest.queued[0].id)
    assert cancelled is not None and cancelled.status == "queued"  # as it was
    assert desk.cancel(rest.queued[0].id) is None


def test_a_refused_order_is_one_line_from_either_desk(desk: TaskDesk) -> None:
    with pytest.raises(TaskRefused, match="there is no zone 'MARS'; zones are LOADING"):
        desk.submit(Order(zone="MARS"))
    assert desk.tasks() == []


def test_a_data_plane_without_the_dispatcher_is_said_as_such(
    aws: None, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A local stack without `vahr up`'s dispatcher answers 404 on /vahr/tasks, as the data
    plane does for any route it lacks: the skill says there is no dispatcher here."""
    from skill_testkit import speech

    from skill import builder as skill_builder
    from skill.config import SkillConfig
    from tests.unit.skill.test_skill_dispatch import intent

    class NoRoute(BaseHTTPRequestHandler):
        def _serve(self) -> None:
            self.rfile.read(int(self.headers.get("Content-Length") or 0))
            body = json.dumps({"code": 404, "message": f"No route for {self.command}"}).encode()
            self.send_response(404)
            self.send_header("Content-Length", str(len(body)))
            self.end_headers()
            self.wfile.write(body)

        do_GET = do_POST = _serve  # noqa: N815

        def log_message(self, *args: object) -> None:
            pass

    server = ThreadingHTTPServer(("127.0.0.1", 0), NoRoute)
    thread = threading.Thread(target=server.serve_forever, daemon=True)
    thread.start()
    try:
        desk = HttpTaskDesk(f"http://127.0.0.1:{server.server_address[1]}")
        monkeypatch.setattr(skill_builder, "task_desk", lambda config: desk)
        handler = skill_builder.make_lambda_handler(SkillConfig(fleet_file=str(SIX_ROBOTS)))
        for event in (
            intent("FleetNavigateIntent", zone=("the shop", "SHOP")),
            intent("TaskQueueIntent"),
        ):
            assert "fleet dispatcher, which is not running here" in speech(handler(event, None))
    finally:
        server.shutdown()
        server.server_close()
        thread.join(timeout=5)
