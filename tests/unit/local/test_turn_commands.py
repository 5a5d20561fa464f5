"""The commands a turn names are the ones the skill published in that turn.

The local data plane tells the Alexa simulator which command ids the skill published
during a turn. A publish the skill gave up on (its client timed out while the broker was
slow to acknowledge, and it told the user it could not reach the robot) that the broker
acknowledged later was named as the next turn's command, for that turn's robots: the soak
counted it lost for a robot it was never sent to, and "unknown" for the one that ran it.
"""

from __future__ import annotations

import json
import threading

from vahr.assistant.commands_seen import CommandLog
from vahr.twin.dataplane import DataPlane
from vahr.twin.meter import Meter
from vahr.twin.shadow_service import ShadowService
from vahr.twin.shadow_store import ShadowStore


def _command(command_id: str) -> bytes:
    return json.dumps({"id": command_id, "action": "navigate", "params": {"zone": "A"}}).encode()


def _data_plane(
    release: threading.Event, waiting: threading.Event | None = None
) -> tuple[DataPlane, CommandLog]:
    def slow_broker(topic: str, payload: bytes, qos: int, retain: bool) -> None:
        if b"slow" in payload:
            if waiting is not None:
                waiting.set()
            release.wait(10)  # the broker's PUBACK is late

    plane = DataPlane(ShadowService(ShadowStore(), lambda _t, _p: None), slow_broker, Meter())
    log = CommandLog(starts_seen=True)
    plane.publish_starters.append(log.begin)
    plane.publish_observers.append(log.observe)
    return plane, log


def test_a_publish_acknowledged_after_its_turn_is_not_named_by_the_next_turn() -> None:
    release, waiting = threading.Event(), threading.Event()
    plane, log = _data_plane(release, waiting)
    # Given a turn whose publish the broker is slow to acknowledge, and the turn ends first
    log.take()
    late = threading.Thread(
        target=plane.handle,
        args=(
            "POST",
            "/topics/vahr%2Frobots%2Fplacebot2%2Fcmd?qos=1",
            _command("slow-from-turn-1"),
        ),
    )
    late.start()
    assert waiting.wait(10)
    assert log.take() == []
    # When the next turn publishes its own command and the late one is acknowledged
    log.take()
    status, _ = plane.handle(
        "POST", "/topics/vahr%2Frobots%2Fplacebot1%2Fcmd?qos=1", _command("turn-2")
    )
    release.set()
    late.join(10)
    # Then the next turn names only its own command
    assert status == 200
    assert log.take() == ["turn-2"]


def test_a_retried_publish_of_one_command_is_named_once() -> None:
    plane, log = _data_plane(threading.Event())
    # Given a turn whose client sent its publish twice (a retry after a timeout)
    log.take()
    for _ in range(2):
        plane.handle("POST", "/topics/vahr%2Frobots%2Fplacebot1%2Fcmd?qos=1", _command("again"))
    # Then the turn names the command once
    assert log.take() == ["again"]
