"""The Alexa simulator served on the local stack: `POST /vahr/say` on the data plane runs
an utterance through the simulated Echo and the skill in-process, and every exchange is
published on `topics.ASSISTANT_TURNS` for the operator station's conversation."""

from __future__ import annotations

import json
import re
from typing import TYPE_CHECKING, Any

import msgspec

from vahr.domain.people import MAX_ID_CHARS, valid_person_id
from vahr.protocol import ProtocolError, topics
from vahr.protocol.station_topics import ORIGIN_PATTERN, Heard

if TYPE_CHECKING:
    from pathlib import Path

    from vahr.assistant.simulator import AlexaSimulator, Turn
    from vahr.twin.stack import LocalStack


def serve_alexa(
    stack: LocalStack,
    *,
    ack_timeout_s: float | None = None,
    model_file: Path | None = None,
    fleet_file: Path | None = None,
    log_level: str = "WARNING",
    locale: str = "en-US",
    users_file: Path | None = None,
    confirm: bool | None = None,
) -> AlexaSimulator:
    """Serve the Alexa simulator (and the skill, in-process) at `POST /vahr/say`, in
    `locale`: its understanding data, and the locale of every request it sends. The skill
    knows the people of `users_file` (None: everyone may do everything) and confirms
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
            user, person = _account(request, "user"), _account(request, "person")
        except ProtocolError as err:
            return 400, {"code": 400, "message": str(err)}
        turn = simulator.say(utterance, origin=origin, heard=heard, user=user, person=person)
        return 200, turn.to_json()

    dataplane.local_routes[("POST", "/vahr/say")] = say
    return simulator


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
