"""The simulated Echo: an utterance in, the skill's spoken answer out.

It strips the wake word and invocation ("Alexa, ask robot fleet to ..."), opens and keeps
a session (attributes carried across turns, Dialog.ElicitSlot answered by a bare slot
value), builds the ASK envelope, and calls the skill handler in-process. One turn at a
time, as one person speaks to one device. Each turn, once answered, goes to `on_turn` (the
local stack publishes it on `topics.ASSISTANT_TURNS` for the operator station).
"""

from __future__ import annotations

import logging
import re
import threading
import time
import uuid
from dataclasses import dataclass, field, replace
from datetime import UTC, datetime
from typing import TYPE_CHECKING, Any

from vahr.local.alexa import envelope
from vahr.local.alexa.localized import invocation_patterns
from vahr.local.alexa.nlu import Understanding, normalize_utterance

if TYPE_CHECKING:
    from collections.abc import Callable

    from vahr.local.alexa.nlu import InteractionModel

log = logging.getLogger(__name__)

_TAGS = re.compile(r"<[^>]+>")
_EXIT = {"exit", "quit", "goodbye", "good bye", "bye"}


@dataclass
class Turn:
    """One exchange, as `vahr say --json` reports it."""

    utterance: str
    speech: str
    intent: str | None
    slots: dict[str, dict[str, str | None]]
    commands: list[str]
    latency_ms: float
    session_open: bool
    request_type: str
    reprompt: str | None = None
    card: dict[str, Any] | None = None
    # Who spoke ("say": the HTTP API; "station", "station-voice": the operator station...).
    origin: str = "say"
    # For speech: what the recognizer heard (transcript, confidence...), as it reported it.
    heard: dict[str, Any] | None = None
    at: datetime = field(default_factory=lambda: datetime.now(UTC))

    def to_json(self) -> dict[str, Any]:
        body = {
            "speech": self.speech,
            "intent": self.intent,
            "slots": self.slots,
            "commands": self.commands,
            "latency_ms": round(self.latency_ms, 1),
            "session_open": self.session_open,
            "request_type": self.request_type,
            "reprompt": self.reprompt,
            "origin": self.origin,
        }
        if self.heard is not None:
            body["heard"] = self.heard
        return body

    def to_message(self) -> dict[str, Any]:
        """The turn as published on `topics.ASSISTANT_TURNS` (`vahr.protocol.station`)."""
        return {**self.to_json(), "utterance": self.utterance, "at": self.at.isoformat()}


@dataclass
class _Session:
    id: str = field(default_factory=lambda: f"amzn1.echo-api.session.{uuid.uuid4()}")
    attributes: dict[str, Any] = field(default_factory=dict)
    turns: int = 0
    eliciting: tuple[Understanding, str] | None = None


def speech_text(output: dict[str, Any] | None) -> str:
    """The words of an outputSpeech object (SSML tags removed)."""
    if not output:
        return ""
    if output.get("type") == "SSML":
        return " ".join(_TAGS.sub(" ", output.get("ssml", "")).split())
    return str(output.get("text", ""))


def strip_invocation(invocation_name: str, utterance: str) -> str:
    """What is said to the skill once the wake word and invocation are removed, in the
    phrasings Alexa supports for a request with an invocation name: "Alexa, ask robot fleet
    to send robot one to zone b", "tell robot fleet that ...", "open robot fleet and ...",
    "... using robot fleet" -> "send robot one to zone b"."""
    text = normalize_utterance(utterance).removeprefix("alexa ")
    # The skill addressed by its name alone, as people do inside a session ("robot fleet,
    # placebot one go to zone b"): the name is no part of the request.
    text = text.removeprefix(normalize_utterance(invocation_name) + " ")
    invocation = re.escape(normalize_utterance(invocation_name))
    for pattern in (
        rf"(?:ask|tell|have)\s+{invocation}(?:\s+(?:to|for|about|if|whether|that))?",
        rf"(?:open|launch|start|use|talk\s+to)\s+{invocation}\s+(?:and|to)",
    ):
        found = re.match(rf"^{pattern}(?:\s+(?P<rest>.*))?$", text)
        if found:
            return found["rest"] or ""
    found = re.match(rf"^(?P<rest>.+?)\s+(?:using|with|from|on|in)\s+{invocation}$", text)
    return found["rest"] if found else text


class AlexaSimulator:
    """Drive `handler` (a Lambda handler) with requests built from spoken utterances.

    `command_log`, when given, returns the ids of commands published since it was last
    called; the simulator asks it after each turn (the data plane records them).
    """

    def __init__(
        self,
        model: InteractionModel,
        handler: Callable[[dict[str, Any], Any], dict[str, Any]],
        *,
        identity: envelope.Identity | None = None,
        command_log: Callable[[], list[str]] | None = None,
        on_turn: Callable[[Turn], None] | None = None,
        locale: str = "en-US",
    ) -> None:
        self.model = model
        self.handler = handler
        self.identity = identity or envelope.Identity()
        self._command_log = command_log or (lambda: [])
        self.on_turn = on_turn
        self._session: _Session | None = None
        self._lock = threading.Lock()
        # The language spoken: the request's locale, and how the skill is addressed in it.
        self.locale = locale
        self._one_shot, self._open = invocation_patterns(model.invocation_name, locale)

    @property
    def session_open(self) -> bool:
        return self._session is not None

    def say(
        self, utterance: str, *, origin: str = "say", heard: dict[str, Any] | None = None
    ) -> Turn:
        """Speak one utterance; returns the skill's answer and what the turn did.

        `origin` says who spoke and `heard` what a recognizer made of their speech; both
        travel with the turn to `on_turn`.
        """
        with self._lock:
            turn = self._say(utterance)
            turn.origin, turn.heard = origin, heard
            self._announce(turn)
            return turn

    def end_session(self) -> Turn | None:
        """End an open session as the user walking away would (reason USER_INITIATED)."""
        with self._lock:
            if self._session is None:
                return None
            turn = self._send("", envelope.session_ended_request(), None)
            self._announce(turn)
            return turn

    def _announce(self, turn: Turn) -> None:
        if self.on_turn is None:
            return
        try:
            self.on_turn(turn)
        except Exception:  # whoever watches must not break the conversation
            log.exception("the turn observer failed")

    def _say(self, utterance: str) -> Turn:
        text = normalize_utterance(utterance)
        opening = self._open.match(text)
        if opening:
            self._session = _Session()
            return self._send(utterance, envelope.launch_request(), None)
        one_shot = self._one_shot.match(text)
        if one_shot:
            rest = one_shot["rest"] or ""
            # Invoking the skill again starts a new session, as it does on an Echo.
            self._session = _Session()
            if not rest:
                return self._send(utterance, envelope.launch_request(), None)
            text = rest
        elif text.startswith("alexa "):
            text = text.removeprefix("alexa ")
        if self._session is not None and text in _EXIT:
            return self._send(utterance, envelope.session_ended_request(), None)
        if self._session is None:
            # A bare utterance with no session: treat it as addressed to this skill, as the
            # developer console's simulator does once the skill is selected.
            self._session = _Session()
        understanding = self._understand(text)
        dialog_state = "IN_PROGRESS" if self._session.eliciting else "STARTED"
        self._session.eliciting = None
        request = envelope.intent_request(self.identity, understanding, dialog_state)
        return self._send(utterance, request, understanding)

    def _understand(self, text: str) -> Understanding:
        assert self._session is not None
        if self._session.eliciting is None:
            return self.model.understand(text)
        pending, slot_name = self._session.eliciting
        # An answer to "which zone?" is the slot value alone (or wrapped in a few words).
        value = self.model.answer(text, pending.intent, slot_name)
        if value is not None:
            return Understanding(
                pending.intent, {**pending.slots, slot_name: value}, pending.declared
            )
        understanding = self.model.understand(text)
        if understanding.intent == pending.intent:
            # The same request said again in full keeps what was already given.
            slots = {**pending.slots, **understanding.slots}
            return replace(understanding, slots=slots)
        return understanding

    def _send(self, utterance: str, request: Any, understanding: Understanding | None) -> Turn:
        session = self._session or _Session()
        event = envelope.envelope(
            self.identity,
            request,
            session_id=session.id,
            new=session.turns == 0,
            attributes=session.attributes,
        )
        event["request"]["locale"] = self.locale
        self._command_log()  # forget commands published outside this turn
        started = time.perf_counter()
        response = self.handler(event, None)
        latency_ms = (time.perf_counter() - started) * 1000
        commands = self._command_log()
        body = response.get("response", {})
        ended = request.object_type == "SessionEndedRequest" or body.get("shouldEndSession", True)
        if ended:
            self._session = None
        else:
            session.turns += 1
            session.attributes = response.get("sessionAttributes") or {}
            session.eliciting = _elicitation(body, understanding)
        slots = {
            name: {"value": value.spoken, "id": value.id}
            for name, value in (understanding.slots.items() if understanding else ())
        }
        reprompt = speech_text((body.get("reprompt") or {}).get("outputSpeech"))
        return Turn(
            utterance=utterance,
            speech=speech_text(body.get("outputSpeech")),
            intent=understanding.intent if understanding else None,
            slots=slots,
            commands=commands,
            latency_ms=latency_ms,
            session_open=self._session is not None,
            request_type=str(request.object_type),
            reprompt=reprompt or None,
            card=body.get("card"),
        )


def _elicitation(
    body: dict[str, Any], understanding: Understanding | None
) -> tuple[Understanding, str] | None:
    """The (intent so far, slot asked for) of a Dialog.ElicitSlot directive, if any."""
    for directive in body.get("directives") or []:
        if directive.get("type") != "Dialog.ElicitSlot" or understanding is None:
            continue
        slot_name = directive.get("slotToElicit")
        updated = directive.get("updatedIntent") or {}
        kept = {
            name: value
            for name, value in understanding.slots.items()
            if (updated.get("slots") or {}).get(name, {}).get("value") is not None
        }
        return (
            Understanding(understanding.intent, kept, understanding.declared, None),
            str(slot_name),
        )
    return None
