"""Fuzz: command messages, into the decoder and executor directly and, through a real
mosquitto, into a real `robot-agent run` process.

Properties: the decoder returns a command or raises `ProtocolError` naming a field; the
agent answers every payload exactly as the decoder judged it (a `rejected` event whose
reason is the decoder's one line, or `accepted`); a rejected payload changes nothing but
`last_command`; the agent never crashes and still answers a ping afterwards.
"""

from __future__ import annotations

import asyncio
import json
import re
import uuid
from typing import TYPE_CHECKING, Any

import msgspec
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from robot_agent.agent import RobotAgent
from robot_agent.backends.sim import SimBackend
from robot_agent.clock import ScaledClock
from robot_agent.core.recent_ids import RecentIds
from tests.fuzz.strategies import command_payloads
from tests.fuzz.tally import TALLY, budget
from tests.integration.agent.harness import AgentProcess, WireTap, command
from vahr.domain import load_fleet
from vahr.protocol import ProtocolError, decode_command, topics

if TYPE_CHECKING:
    from collections.abc import Callable, Iterator

    from vahr.twin.broker import Mosquitto

FLEET = load_fleet()
# A field is a dotted path of names and indexes, or the whole `payload`.
# A field is a dotted path of names and indexes, or the whole `payload`; its last part may
# be a key the sender made up (`params.colour: is not a known field`), shown cut short.
FIELD = re.compile(r"^[A-Za-z_][\w]*(\.[\w]+)*(\.[^\n]{1,40})?$")
STATE_FIELDS = ("status", "zone", "cargo", "destination", "task", "pose")


def verdict(payload: bytes) -> ProtocolError | None:
    try:
        decode_command(payload, FLEET)
    except ProtocolError as err:
        return err
    return None


@given(payload=command_payloads())
@settings(max_examples=budget(400))
def test_the_decoder_accepts_or_names_the_field(payload: bytes) -> None:
    error = verdict(payload)
    if error is None:
        TALLY.accepted("command decoder")
        return
    assert FIELD.match(error.field), error.field
    assert str(error) == f"{error.field}: {error.reason}"
    assert "\n" not in str(error) and error.reason
    assert len(str(error)) < 400  # fits a `rejected` event well inside the 8 KB limit
    TALLY.rejected("command decoder", error.field)


class MemoryLink:
    """A `Link` kept in memory: routes by exact topic, records what is published."""

    def __init__(self) -> None:
        self.routes: dict[str, list[Callable[[str, bytes], None]]] = {}
        self.published: list[tuple[str, bytes]] = []

    def publish(self, topic: str, payload: bytes, *, retain: bool = False) -> None:
        self.published.append((topic, payload))

    def add_route(self, topic_filter: str, handler: Callable[[str, bytes], None]) -> None:
        self.routes.setdefault(topic_filter, []).append(handler)

    def on_connected(self, callback: Callable[[bool], None]) -> None:
        pass

    def on_disconnected(self, callback: Callable[[str], None]) -> None:
        pass

    def deliver(self, topic: str, payload: bytes) -> None:
        for handler in self.routes.get(topic, []):
            handler(topic, payload)

    def events(self) -> list[dict[str, Any]]:
        return [json.loads(p) for t, p in self.published if t == topics.robot_events("placebot1")]


def _agent(link: MemoryLink) -> RobotAgent:
    clock = ScaledClock(50.0)
    agent = RobotAgent(
        thing="placebot1",
        fleet=FLEET,
        link=link,
        backend=SimBackend(start=FLEET.robot("placebot1").start, clock=clock),
        clock=clock,
        recent_ids=RecentIds(None),
    )
    agent.attach()
    return agent


def _where(agent: RobotAgent) -> dict[str, Any]:
    state = msgspec.to_builtins(agent.executor.state)
    return {name: state.get(name) for name in STATE_FIELDS}


DELTA = topics.shadow("placebot1", "update/delta")
INBOUND = [topics.robot_cmd("placebot1"), topics.FLEET_CMD, DELTA]


@given(
    inputs=st.lists(st.tuples(st.sampled_from(INBOUND), command_payloads()), min_size=1, max_size=4)
)
@settings(max_examples=budget(150))
def test_the_agent_answers_each_payload_as_the_decoder_judged_it(
    inputs: list[tuple[str, bytes]],
) -> None:
    async def scenario() -> None:
        link = MemoryLink()
        agent = _agent(link)
        executed: set[str] = set()
        for topic, raw in inputs:
            # On the delta topic a command travels inside desired state.
            payload = _delta(raw) if topic == DELTA else raw
            before, seen = _where(agent), len(link.events())
            link.deliver(topic, payload)
            # The answer (accepted or rejected) is synchronous; a running task's own events
            # (progress, failed, ...) may follow at any await, so only answers are compared.
            answers = [e for e in link.events()[seen:] if e["event"] in ("accepted", "rejected")]
            expected = _expected(topic, raw)
            if expected is None:
                assert answers == []
            elif isinstance(expected, ProtocolError):
                assert [e["event"] for e in answers] == ["rejected"], answers
                assert answers[0]["reason"] == str(expected)
                assert _where(agent) == before
                assert agent.executor.state.last_command is not None
                assert agent.executor.state.last_command.result == "rejected"
                TALLY.rejected("command executor", expected.field)
            elif expected in executed:
                assert answers == []  # the same id twice is executed once
            else:
                executed.add(expected)
                assert len(answers) == 1, answers
                TALLY.accepted("command executor")
            await asyncio.sleep(0)
        await agent.shut_down()

    asyncio.run(scenario())


def _deep(raw: bytes) -> bool:
    """Nested so deep that whether a parser manages it depends on the caller's own stack
    depth; such a document never carries a command here (it is a bare array, or an object
    without `state`)."""
    return b"[[[[[[[[[[" in raw


def _delta(raw: bytes) -> bytes:
    """What the shadow service would send on `update/delta` with `raw` as the desired
    command; garbage (or a document too deep to nest) is sent as it is."""
    try:
        json.loads(raw)
    except (ValueError, RecursionError):
        return raw
    return raw if _deep(raw) else b'{"state":{"command":' + raw + b"}}"


def _expected(topic: str, raw: bytes) -> ProtocolError | str | None:
    """None: no answer expected; a ProtocolError: a rejection; an id: an answer."""
    if topic == DELTA:
        if _delta(raw) == raw:
            return None  # no command in desired state
        inner = json.loads(raw)
        if inner is None:
            return None  # {"command": null}
        raw = msgspec.json.encode(inner)  # as the agent re-encodes desired state
    try:
        return decode_command(raw, FLEET).id
    except ProtocolError as err:
        return err


# -- through the broker into a real agent process ------------------------------------------


@pytest.fixture(scope="module")
def wire(tmp_path_factory: pytest.TempPathFactory) -> Iterator[tuple[WireTap, AgentProcess]]:
    from vahr.plumbing.ports import free_port
    from vahr.twin.broker import BrokerConfig, Mosquitto

    base = tmp_path_factory.mktemp("fuzz-agent")
    broker: Mosquitto = Mosquitto(BrokerConfig(state_dir=base / "broker", plain_port=free_port()))
    broker.start()
    tap = WireTap(broker.config.plain_port or 0)
    agent = AgentProcess(
        "--thing", "placebot1", "--broker", str(broker.plain_url), "--sim-speed-factor", "50",
        state_dir=base / "state", log_file=base / "agent.log",
    )  # fmt: skip
    try:
        tap.wait_for(lambda m: m.topic == topics.robot_presence("placebot1"), 30)
        yield tap, agent
    finally:
        agent.stop()
        tap.close()
        broker.stop()


# The agent remembers the last 1,000 command ids (RecentIds): the model of what it will
# take as a duplicate is the same bounded set.
EXECUTED_OVER_THE_WIRE = RecentIds(None)


def _ping(tap: WireTap, agent: AgentProcess) -> str:
    """Send a ping and wait for the agent's answer; its id."""
    ping_id = f"ping-{uuid.uuid4().hex[:8]}"
    mark = tap.mark()
    tap.publish(topics.robot_cmd("placebot1"), command(ping_id, "ping"))
    try:
        tap.event("placebot1", "accepted", ping_id, timeout_s=10, after=mark)
    except TimeoutError as err:
        # What the agent did meanwhile says whose side the silence is on.
        code = agent.process.poll()
        state = "running" if code is None else f"exited with {code}"
        log = agent.log()[-1500:]
        raise AssertionError(f"{err}; the agent is {state}; its log ends:\n{log}") from err
    return ping_id


@given(payload=command_payloads())
@settings(max_examples=budget(40))
def test_a_real_agent_survives_any_payload_on_its_command_topic(
    wire: tuple[WireTap, AgentProcess], payload: bytes
) -> None:
    tap, agent = wire
    # Given the agent has answered everything sent so far
    mark = tap.mark()
    # When a payload arrives on its command topic, followed by a ping
    tap.publish(topics.robot_cmd("placebot1"), payload)
    ping_id = _ping(tap, agent)
    # Then it answered exactly as the decoder judged, and is alive and serving
    answers = [
        m.json()
        for m in tap.messages[mark:]
        if m.topic == topics.robot_events("placebot1")
        and m.json()["event"] in ("accepted", "rejected")
        and not str(m.json().get("command_id", "")).startswith("ping-")
    ]
    expected = _expected(topics.robot_cmd("placebot1"), payload)
    if isinstance(expected, ProtocolError):
        assert [e["event"] for e in answers] == ["rejected"], answers
        assert answers[0]["reason"] == str(expected)
        TALLY.rejected("command over MQTT into robot-agent", expected.field)
    elif not EXECUTED_OVER_THE_WIRE.add(str(expected)):
        assert answers == []  # the same id twice is executed once
    else:
        assert len(answers) == 1, answers
        TALLY.accepted("command over MQTT into robot-agent")
    # The agent remembers the ping's id after the payload's, as any command's, and so must
    # its model: a thousand pings later, an id sent at the start is new to the agent again.
    EXECUTED_OVER_THE_WIRE.add(ping_id)
    assert agent.process.poll() is None, agent.log()[-2000:]
