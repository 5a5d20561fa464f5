"""The Alexa simulator served on the local stack: `POST /vahr/say` on the data plane runs
an utterance through the simulated Echo and the skill in-process, and every exchange is
published on `topics.ASSISTANT_TURNS` for the operator station's conversation.

A say request may carry `timeout_s`, how long its asker waits for the answer (`vahr say`
sends it). The turn waits for the system to be ready (`Readiness`) only as long as it can
still finish in that time; a turn that cannot start is refused with 503 and does nothing,
and a command it would publish after the asker stopped waiting is refused at the data
plane (`vahr.assistant.deadline`). So a reply that says a request failed is never followed
by a robot carrying it out."""

from __future__ import annotations

import json
import re
from typing import TYPE_CHECKING, Any

import msgspec

from vahr.assistant.deadline import TurnDeadline, TurnNotStarted
from vahr.domain.people import MAX_ID_CHARS, valid_person_id
from vahr.protocol import ProtocolError, topics
from vahr.protocol.station_topics import ORIGIN_PATTERN, Heard
from vahr.twin.dataplane import ApiError

if TYPE_CHECKING:
    from pathlib import Path

    from vahr.assistant.simulator import AlexaSimulator, Turn
    from vahr.local.readiness import Readiness
    from vahr.twin.stack import LocalStack

# How long a say request that gives no `timeout_s` waits for the system to be ready.
DEFAULT_START_WAIT_S = 30.0


def serve_alexa(
    stack: LocalStack,
    *,
    ack_timeout_s: float | None = None,
    model_file: Path | None = None,
    fleet_file: Path | None = None,
    log_level: str = "WARNING",
    locale: str = "en-US",
    readiness: Readiness | None = None,
    users_file: Path | None = None,
    confirm: bool | None = None,
) -> AlexaSimulator:
    """Serve the Alexa simulator (and the skill, in-process) at `POST /vahr/say`, in
    `locale`: its understanding data, and the locale of every request it sends. A say
    request waits for `readiness` (every robot online, the language model built). The
    skill knows the people of `users_file` (None: everyone may do everything) and confirms
    fleet-wide commands as `confirm` says (None: as the fleet file says, else when people
    are known).

    A say request may name the Alexa account speaking (`user`, `vahr say --user`) and the
    voice recognised (`person`); each account has its own session."""
    # The NLU's libraries load here, not when `vahr.local` is imported.
    from vahr.assistant.commands_seen import CommandLog
    from vahr.assistant.envelope import Identity
    from vahr.assistant.nlu import InteractionModel
    from vahr.assistant.simulator import AlexaSimulator
    from vahr.assistant.skill import load_skill_handler
    from vahr.assistant.understanding import load_understanding

    dataplane = stack.dataplane
    assert dataplane is not None, "start() first"
    log = CommandLog(starts_seen=True)
    dataplane.publish_starters.append(log.begin)
    dataplane.publish_observers.append(log.observe)
    # The classifier loads (or trains, when its cache is cold) while the rest starts;
    # the first utterance waits for it.
    understanding = load_understanding(locale)
    model = InteractionModel.load(model_file, background=True, understanding=understanding)
    # The skill serves one skill id, as on Lambda, and the simulated Echo's envelopes carry
    # it: the handler's check runs here too (skill.skill_gate).
    identity = Identity()
    handler = load_skill_handler(
        stack.api_url,
        ack_timeout_s=ack_timeout_s,
        skill_id=identity.skill_id,
        fleet_file=str(fleet_file) if fleet_file else None,
        log_level=log_level,
        users_file=str(users_file) if users_file else None,
        confirm=confirm,
    )

    def publish_turn(turn: Turn) -> None:
        # Every exchange, whoever spoke, for the operator station's conversation.
        payload = json.dumps(turn.to_message(), separators=(",", ":")).encode()
        stack.publish_service(topics.ASSISTANT_TURNS, payload)

    simulator = AlexaSimulator(
        model,
        handler,
        identity=identity,
        command_log=log.take,
        on_turn=publish_turn,
        locale=locale,
    )

    def gate(topic: str, payload: bytes) -> None:
        # Before the command log: a refused command is no command of the turn.
        if not simulator.may_publish() and _is_command(topic):
            raise ApiError(
                504, "the person who asked stopped waiting for the answer; the command is not sent"
            )

    dataplane.publish_starters.insert(0, gate)

    def say(request: dict[str, Any]) -> tuple[int, dict[str, Any]]:
        utterance = request.get("utterance")
        if request.get("end_session"):
            ended = simulator.end_session()
            return 200, ended.to_json() if ended else {"session_open": False}
        if not isinstance(utterance, str) or not utterance.strip():
            return 400, {"code": 400, "message": "utterance: a non-empty string is required"}
        asked = request.get("locale", locale)
        if asked != locale:
            message = f"locale: this system speaks {locale}; start it with vahr up --locale {asked}"
            return 400, {"code": 400, "message": message}
        try:
            origin, heard = _speaker(request)
            deadline = _deadline(request)
            user, person = _account(request, "user"), _account(request, "person")
        except ProtocolError as err:
            return 400, {"code": 400, "message": str(err)}
        if readiness is not None:
            waiting = deadline.start_left() if deadline else DEFAULT_START_WAIT_S
            if not readiness.wait(max(0.0, waiting)):
                what = "; ".join(readiness.awaiting())
                message = f"vahr up is still starting (waiting for {what}); nothing was sent"
                return 503, {"code": 503, "message": message}
        try:
            turn = simulator.say(
                utterance, origin=origin, heard=heard, deadline=deadline, user=user, person=person
            )
        except TurnNotStarted as err:
            return 503, {"code": 503, "message": str(err)}
        return 200, turn.to_json()

    dataplane.local_routes[("POST", "/vahr/say")] = say
    return simulator


def _deadline(request: dict[str, Any]) -> TurnDeadline | None:
    """The turn's deadline from the request's `timeout_s` (None when it gives none)."""
    timeout = request.get("timeout_s")
    if timeout is None:
        return None
    if isinstance(timeout, bool) or not isinstance(timeout, int | float) or not timeout > 0:
        raise ProtocolError("timeout_s", "must be a number of seconds more than 0")
    return TurnDeadline.within(float(timeout))


def _is_command(topic: str) -> bool:
    parsed = topics.parse_robot_topic(topic)
    return topic == topics.FLEET_CMD or (parsed is not None and parsed[1] == "cmd")


def _account(request: dict[str, Any], field: str) -> str | None:
    """An Alexa userId or personId from a say request, or None when not given."""
    value = request.get(field)
    if value is None:
        return None
    if not isinstance(value, str) or not valid_person_id(value):
        raise ProtocolError(field, f"an Alexa id is 1 to {MAX_ID_CHARS} printable characters")
    return value


def _speaker(request: dict[str, Any]) -> tuple[str, dict[str, Any] | None]:
    """Who spoke (`origin`, default "say") and what a recognizer heard, from a say request."""
    origin = request.get("origin", "say")
    if not isinstance(origin, str) or not re.fullmatch(ORIGIN_PATTERN, origin):
        raise ProtocolError("origin", "must be a short lower-case word such as station-voice")
    heard = request.get("heard")
    if heard is None:
        return origin, None
    try:
        checked = msgspec.convert(heard, Heard)
    except msgspec.ValidationError as err:
        raise ProtocolError("heard", str(err)) from err
    return origin, msgspec.to_builtins(checked)
