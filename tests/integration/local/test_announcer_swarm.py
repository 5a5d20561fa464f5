"""One fault, one announcement, under a 100-robot swarm with faults injected.

A real mosquitto carries a swarm of 100 simulated robots (tests/support/swarm_runner.py) and the
local announcer (`vahr.local.announce_host.LocalAnnouncer`, as `vahr up` runs it). Ten robots
get stuck, ten fail their task and ten go offline; each fault also reaches the announcer
more than once before it clears (a stuck task ends as failed, a QoS 1 redelivery, a last
will published twice). Each fault is told exactly once, on the announcements topic too;
once a fault clears, the same robot's next fault is told again.
"""

from __future__ import annotations

import threading
import time
from collections import Counter
from datetime import UTC, datetime
from typing import TYPE_CHECKING

import pytest

from robot_agent.backends.sim import SimBackend
from robot_agent.config import ExecutorSettings
from tests.integration.agent.harness import ShadowResponder, WireTap, command
from tests.support.swarm_runner import SwarmThread, swarm_fleet
from vahr.announce import settings_from
from vahr.local.announce_host import LocalAnnouncer
from vahr.plumbing.mqtt import MqttEndpoint
from vahr.protocol import topics
from vahr.protocol.announcements import decode_announcement

if TYPE_CHECKING:
    from collections.abc import Callable, Iterator

    from vahr.protocol.announcements import Announcement
    from vahr.twin.broker import Mosquitto

pytestmark = [pytest.mark.slow, pytest.mark.timeout(240)]

COUNT = 100
SPEED = 20
# A busy machine must not make an idle or driving robot look stuck: only the robots told
# to get stuck do (60 simulated seconds without progress, 3 s of wall time at x20).
PATIENT = ExecutorSettings(stuck_after_s=60)
# Room for every fault at once: this test is about one announcement per fault, not about
# the rate limit (tests/unit/announce covers that).
SETTINGS = settings_from({"max_per_window": 100})
STUCK = [f"swarm{n:04d}" for n in range(1, 11)]
FAILED = [f"swarm{n:04d}" for n in range(11, 21)]
OFFLINE = [f"swarm{n:04d}" for n in range(21, 31)]


class Heard:
    """The announcements the announcer told, as its listeners get them."""

    def __init__(self) -> None:
        self.told: list[Announcement] = []
        self._cond = threading.Condition()

    def __call__(self, announcement: Announcement) -> None:
        with self._cond:
            self.told.append(announcement)
            self._cond.notify_all()

    def wait_for(self, count: int, timeout_s: float = 60.0) -> list[Announcement]:
        with self._cond:
            if not self._cond.wait_for(lambda: len(self.told) >= count, timeout_s):
                raise AssertionError(f"{len(self.told)} of {count} announcements: {self.kinds()}")
            return list(self.told)

    def kinds(self) -> Counter[tuple[str | None, str]]:
        return Counter((a.thing, a.kind) for a in self.told)


@pytest.fixture
def swarm(mosquitto: Mosquitto) -> Iterator[SwarmThread]:
    port = mosquitto.config.plain_port or 0
    shadows = ShadowResponder(port)
    try:
        with SwarmThread(
            broker=str(mosquitto.plain_url), count=COUNT, speed_factor=SPEED, settings=PATIENT,
            listen_to_peers=False,
        ) as running:  # fmt: skip
            yield running
    finally:
        shadows.close()


@pytest.fixture
def tap(mosquitto: Mosquitto) -> Iterator[WireTap]:
    wire = WireTap(mosquitto.config.plain_port or 0)
    yield wire
    wire.close()


@pytest.fixture
def heard(mosquitto: Mosquitto, swarm: SwarmThread) -> Iterator[Heard]:
    # Started after the swarm, stopped before it: the swarm's goodbye (every robot's
    # offline presence) is not part of the test.
    announcer = LocalAnnouncer(
        MqttEndpoint(port=mosquitto.config.plain_port or 0), swarm_fleet(COUNT), SETTINGS
    )
    listener = Heard()
    announcer.announcer.add_listener(listener)
    with announcer:
        yield listener


def on_robots(swarm: SwarmThread, things: list[str], fault: Callable[[SimBackend], None]) -> None:
    """Inject `fault` into each robot's simulator before it is sent off. The injection only
    sets a flag the simulator reads on its next step; the command that follows it over the
    broker orders the two."""
    assert swarm.swarm is not None
    for thing in things:
        backend = swarm.swarm.agents[thing].executor.backend
        assert isinstance(backend, SimBackend)
        fault(backend)


def send(tap: WireTap, thing: str, command_id: str, zone: str) -> None:
    tap.publish(topics.robot_cmd(thing), command(command_id, "navigate", {"zone": zone}))


def presence(tap: WireTap, thing: str, *, online: bool) -> None:
    """What a robot's last will (or its return) says, retained, as the broker sends it."""
    at = datetime.now(UTC).isoformat().replace("+00:00", "Z")
    tap.publish(topics.robot_presence(thing), {"online": online, "at": at}, retain=True)


def redeliver(tap: WireTap, thing: str, kind: str) -> None:
    """Publish a robot's last `kind` event again, as a QoS 1 redelivery would."""
    [last] = [e for e in tap.events(thing) if e["event"] == kind][-1:]
    tap.publish(topics.robot_events(thing), last)


def assert_stays(heard: Heard, expected: Counter[tuple[str | None, str]]) -> None:
    """The announcements are exactly `expected`, and a moment later still are."""
    heard.wait_for(sum(expected.values()))
    time.sleep(1.5)  # late duplicates would have arrived by now
    assert heard.kinds() == expected


def test_one_fault_one_announcement_under_a_100_robot_swarm(
    swarm: SwarmThread, tap: WireTap, heard: Heard
) -> None:
    assert len(swarm.things) == COUNT
    mark = len(tap.messages)
    # Given ten robots that will get stuck and ten whose goal will abort, all sent off
    on_robots(swarm, STUCK, lambda backend: backend.inject_stuck())
    on_robots(swarm, FAILED, lambda backend: backend.inject_failure("an injected fault"))
    for thing in STUCK + FAILED:
        send(tap, thing, f"{thing}-1", "A")
    # and ten robots whose connection drops: the last will, and the same will again
    for thing in OFFLINE:
        presence(tap, thing, online=False)
        presence(tap, thing, online=False)
    # When every stuck task has ended as failed (the same fault, told again) and every
    # failure has been redelivered
    for thing in STUCK:
        tap.event(thing, "failed", f"{thing}-1", timeout_s=60)
    for thing in FAILED:
        tap.event(thing, "failed", f"{thing}-1", timeout_s=60)
        redeliver(tap, thing, "failed")
    # Then each fault was announced exactly once, naming its robot
    first_round = Counter(
        [(t, "stuck") for t in STUCK] + [(t, "failed") for t in FAILED]
        + [(t, "offline") for t in OFFLINE]
    )  # fmt: skip
    assert_stays(heard, first_round)
    stuck = next(a for a in heard.told if a.thing == STUCK[0])
    assert stuck.speech == "Swarm 1 is stuck on its way to zone A and needs your help."
    failed = next(a for a in heard.told if a.thing == FAILED[0])
    assert (
        failed.speech
        == "Swarm 11 could not finish its task: goal to zone A aborted: an injected fault."
    )
    # And each went out once on the announcements topic, as the station hears them
    on_wire = [
        decode_announcement(m.payload)
        for m in tap.messages[mark:]
        if m.topic == topics.ASSISTANT_ANNOUNCEMENTS
    ]
    assert sorted(a.id for a in on_wire) == sorted(a.id for a in heard.told)

    # When one robot of each kind recovers (a new command, its connection back) and then
    # has a new fault of the same kind
    again_stuck, again_failed, again_offline = STUCK[0], FAILED[0], OFFLINE[0]
    on_robots(swarm, [again_stuck], lambda backend: backend.inject_stuck())
    on_robots(swarm, [again_failed], lambda backend: backend.inject_failure("an injected fault"))
    send(tap, again_stuck, f"{again_stuck}-2", "B")
    send(tap, again_failed, f"{again_failed}-2", "B")
    presence(tap, again_offline, online=True)
    tap.event(again_stuck, "failed", f"{again_stuck}-2", timeout_s=60)
    tap.event(again_failed, "failed", f"{again_failed}-2", timeout_s=60)
    presence(tap, again_offline, online=False)
    # Then each new fault is told once more, and nothing else
    assert_stays(
        heard,
        first_round
        + Counter(
            [(again_stuck, "stuck"), (again_failed, "failed"), (again_offline, "offline")]
        ),  # fmt: skip
    )
    ids = [a.id for a in heard.told]
    assert len(set(ids)) == len(ids)
