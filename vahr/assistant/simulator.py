"""The simulated Echo: an utterance in, the skill's spoken answer out.

It strips the wake word and invocation ("Alexa, ask robot fleet to ..."), opens and keeps
a session (attributes carried across turns), builds the ASK envelope, and calls the skill
handler in-process. One turn at a time, as one person speaks to one device. Each turn, once
answered, goes to `on_turn` (the local stack publishes it on `topics.ASSISTANT_TURNS` for
the operator station).

The dialog is kept as Alexa keeps it (`dialogState` STARTED, then IN_PROGRESS):

- after Dialog.ElicitSlot the answer fills the slot asked for, by its value alone ("zone
  b") or in a whole sentence; slot values the answer carries replace the intent's ("robot
  two please go to zone a" after "which robot?" for zone D goes to zone A); an answer that
  is another request starts that intent instead;
- after Dialog.ConfirmSlot or Dialog.ConfirmIntent a yes or a no comes back as the same
  intent with the slot's or the intent's confirmationStatus CONFIRMED or DENIED; anything
  else is a request of its own;
- a request whose slot roles the NLU is unsure of (`Understanding.needs_confirmation`:
  which robot goes first, which zone is for sunny weather) is confirmed by the simulator
  itself before the skill hears of it, as Alexa says an intent's confirmation prompt under
  auto-delegation ("Placebot one to zone d, then placebot two to zone d: is that right?");
  the yes or no then reaches the skill as the intent CONFIRMED or DENIED. This is the
  simulator's NLU only: on AWS, Alexa's own NLU decides what it is sure of.

Silence is answered by the device itself (nothing reaches the skill); a ramble longer than
any request the model knows reaches it as AMAZON.FallbackIntent, so nothing moves. The
skill's last command (`vahr.protocol.conversation`) outlives the session for the same
origin for a short window, so a correction said just after a one-shot request works.

Each Alexa account (`user`, the envelope's userId; the Echo's own by default) has a session
of its own, as each person has their own Echo: one person's open question is never
answered by another's words. `person` is the personId Alexa gives when it recognised the
voice; people recognised on one account share its session, as on one Echo, and the skill
itself tells their answers apart. The handler is called with a
`vahr.protocol.audit.RequestSource` as its context: the channel (from the origin) and the
words, which the skill's audit record keeps.
"""

from __future__ import annotations

import logging
import re
import threading
import time
import uuid
from dataclasses import dataclass, field, replace
from datetime import UTC, datetime
from functools import cache
from pathlib import Path
from typing import TYPE_CHECKING, Any

import yaml

from vahr.assistant import envelope
from vahr.assistant.deadline import TurnDeadline, TurnNotStarted
from vahr.assistant.localized import invocation_patterns
from vahr.assistant.nlu import Understanding, normalize_utterance
from vahr.domain.invocation import FALLBACK_INTENT
from vahr.protocol.audit import RequestSource, channel_of
from vahr.protocol.conversation import CORRECTION_WINDOW_S, LAST_COMMAND_ATTRIBUTE, speaker

if TYPE_CHECKING:
    from collections.abc import Callable, Mapping

    from vahr.assistant.nlu import InteractionModel

log = logging.getLogger(__name__)

_TAGS = re.compile(r"<[^>]+>")
_PLACEHOLDER = re.compile(r"\{(\w+)\}")
# How a person answers yes or no, and how the device says a reading back, per locale
# ("confirmation-<locale>.yaml"; a locale without one is read with en-US's).
_DATA = Path(__file__).with_name("data")
_DEFAULT_LOCALE = "en-US"
# What the device says when it heard nothing: Alexa answers silence itself, the skill never
# hears of it.
SILENCE = "I didn't hear anything, so I sent nothing to the robots."
# A request is read only when it is at most this many times as long as the longest sentence
# the model learnt from (21 words for the default model, so 42: about 17 s of speech at 150
# words a minute); anything longer is a ramble no intent describes.
RAMBLE_FACTOR = 2
ELICIT = "Dialog.ElicitSlot"
CONFIRM_SLOT = "Dialog.ConfirmSlot"
CONFIRM_INTENT = "Dialog.ConfirmIntent"


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
    # The Alexa account that spoke, when not the Echo's own.
    user: str | None = None

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
        if self.user is not None:
            body["user"] = self.user
        return body

    def to_message(self) -> dict[str, Any]:
        """The turn as published on `topics.ASSISTANT_TURNS` (`vahr.protocol.station_topics`)."""
        return {**self.to_json(), "utterance": self.utterance, "at": self.at.isoformat()}


@dataclass(frozen=True)
class PendingDialog:
    """What the skill asked last: the intent so far (as its updatedIntent left it), the
    directive, the slot asked about (None for Dialog.ConfirmIntent), and the reprompt, what
    the device says when it did not catch the answer."""

    understanding: Understanding
    directive: str
    slot: str | None
    reprompt: str | None = None


@dataclass
class _Session:
    id: str = field(default_factory=lambda: f"amzn1.echo-api.session.{uuid.uuid4()}")
    attributes: dict[str, Any] = field(default_factory=dict)
    turns: int = 0
    pending: PendingDialog | None = None


@cache
def _confirmation_document(locale: str) -> dict[str, Any]:
    file = _DATA / f"confirmation-{locale}.yaml"
    if not file.is_file():
        file = _DATA / f"confirmation-{_DEFAULT_LOCALE}.yaml"
    document: dict[str, Any] = yaml.safe_load(file.read_text(encoding="utf-8"))
    return document


@cache
def _confirmation_phrases(locale: str) -> dict[str, frozenset[str]]:
    document = _confirmation_document(locale)
    return {
        status: frozenset(normalize_utterance(p, locale) for p in document[key])
        for status, key in (("CONFIRMED", "confirmed"), ("DENIED", "denied"))
    }


def confirmation_phrases(locale: str = _DEFAULT_LOCALE) -> list[str]:
    """Every yes and no the simulated Echo takes as an answer to a yes-or-no question (as
    a vocabulary of what people say to it)."""
    document = _confirmation_document(locale)
    return [str(phrase) for key in ("confirmed", "denied") for phrase in document[key]]


def confirmation_prompt(
    understanding: Understanding,
    slot_types: Mapping[str, str] | None = None,
    locale: str = _DEFAULT_LOCALE,
) -> str:
    """What the simulated Echo says to confirm `understanding`, its values by name (a slot
    with no value by the words for its type in `slot_types`, slot name -> type)."""
    document = _confirmation_document(locale)
    names = {name: value.canonical or value.spoken for name, value in understanding.slots.items()}
    template = document["readings"].get(understanding.intent)
    if template is None:
        heard = [names[name] for name in understanding.declared or names if name in names]
        return str(document["any"]).format(names=", ".join(heard))
    missing: dict[str, str] = document["missing"]
    types = slot_types or {}
    filled = {
        name: names.get(name) or missing.get(types.get(name, ""), missing["any"])
        for name in _PLACEHOLDER.findall(str(template))
    }
    sentence = " ".join(str(template).format_map(filled).split())
    return sentence[:1].upper() + sentence[1:]


def confirmation_of(text: str, locale: str = _DEFAULT_LOCALE) -> str | None:
    """CONFIRMED for a yes, DENIED for a no, None for anything else."""
    said = normalize_utterance(text, locale)
    phrases = _confirmation_phrases(locale)
    return next((status for status, ps in phrases.items() if said in ps), None)


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
        clock: Callable[[], float] = time.monotonic,
    ) -> None:
        self.model = model
        language = model.language
        self._exits = {normalize_utterance(w, language.locale) for w in language.exits}
        self.handler = handler
        self.identity = identity or envelope.Identity()
        self._command_log = command_log or (lambda: [])
        self.on_turn = on_turn
        # Alexa account (userId) -> its open session.
        self._sessions: dict[str, _Session] = {}
        self._lock = threading.Lock()
        self._clock = clock
        # (account, speaker) -> (when, the skill's last command) of their latest turn.
        self._recent: dict[tuple[str, str], tuple[float, Any]] = {}
        self._origin = "say"
        # The deadline of the turn under way, when its asker said how long they wait.
        self._deadline: TurnDeadline | None = None
        # Who speaks in the turn under way: the account, and the recognised person if any.
        self._user = self.identity.user_id
        self._person: str | None = None
        longest = max((len(text.split()) for text in model.training[0]), default=0)
        self._longest_words = RAMBLE_FACTOR * longest
        # The language spoken: the request's locale, and how the skill is addressed in it.
        self.locale = locale
        self._one_shot, self._open = invocation_patterns(model.invocation_name, locale)

    @property
    def _session(self) -> _Session | None:
        """The session of the account speaking now."""
        return self._sessions.get(self._user)

    @_session.setter
    def _session(self, session: _Session | None) -> None:
        if session is None:
            self._sessions.pop(self._user, None)
        else:
            self._sessions[self._user] = session

    def _account(self, user: str | None) -> str:
        return user or self.identity.user_id

    @property
    def session_open(self) -> bool:
        return self.session_open_for(None)

    def session_open_for(self, user: str | None) -> bool:
        """Whether `user`'s account (the Echo's own for None) has a session open."""
        return self._account(user) in self._sessions

    @property
    def pending(self) -> PendingDialog | None:
        """What the skill asked and waits for an answer to, in the open session."""
        return self.pending_for(None)

    def pending_for(self, user: str | None) -> PendingDialog | None:
        """What the skill asked `user`'s account (the Echo's own for None) and waits for."""
        session = self._sessions.get(self._account(user))
        return session.pending if session else None

    def say(
        self,
        utterance: str,
        *,
        origin: str = "say",
        heard: dict[str, Any] | None = None,
        understanding: Understanding | None = None,
        deadline: TurnDeadline | None = None,
        user: str | None = None,
        person: str | None = None,
    ) -> Turn:
        """Speak one utterance; returns the skill's answer and what the turn did.

        `origin` says who spoke and `heard` what a recognizer made of their speech; both
        travel with the turn to `on_turn`. `user` is the Alexa account speaking (the Echo's
        own by default) and `person` the recognised voice, if any. `understanding`, when
        given, is used instead of understanding the words (a recognizer that weighed
        several hearings built it); while a slot is elicited it is an answer when its
        intent is the pending one or it names the slot alone (`pending` says which). With a
        `deadline`, a turn that cannot start by its `start_by` (another turn held the
        simulator, the language model was still being built) raises TurnNotStarted having
        done nothing, and `may_publish` says whether its commands may still go out.
        """
        with self._lock:
            if deadline is not None and deadline.start_left() < 0:
                raise TurnNotStarted(
                    "the assistant could not start on it while you waited; nothing was sent "
                    "to the robots"
                )
            self._origin = origin
            self._user, self._person = self._account(user), person
            self._deadline = deadline
            try:
                turn = self._say(utterance, understanding)
            finally:
                self._deadline = None
            turn.origin, turn.heard = origin, heard
            turn.user = user
            self._announce(turn)
            return turn

    def may_publish(self) -> bool:
        """Whether a command of the turn under way may still be sent: False once the
        person who spoke has stopped waiting for the answer (the data plane then refuses
        it, so what they were told failed is never done later)."""
        deadline = self._deadline
        return deadline is None or deadline.may_publish()

    def reading(self, utterance: str, user: str | None = None) -> Understanding:
        """What `utterance` would be understood as if said now, without saying it: while
        the skill asks for a slot, as the answer to that question (as `say` reads it); while
        it asks a yes-or-no question, a yes as the intent it confirms and a no as
        AMAZON.NoIntent; else as a request (the invocation taken off). Push-to-talk weighs
        each of its N best this way, so an answer ("zone b" to "Zone B or zone D?", "yes" to
        "Placebot two instead?") is weighed as one, and readings split between yes and no
        are not sure of either."""
        with self._lock:
            pending = self.pending_for(user)
        text = strip_invocation(self.model.invocation_name, utterance)
        if pending is not None and pending.directive == ELICIT and pending.slot is not None:
            return self._answer(text, pending.understanding, pending.slot)
        return self.yes_or_no(text, user) or self.model.understand(text)

    def yes_or_no(self, utterance: str, user: str | None = None) -> Understanding | None:
        """`utterance` as the answer to the yes-or-no question under way: a yes as the
        intent it confirms, a no as AMAZON.NoIntent; None when no such question is asked or
        `utterance` is neither."""
        with self._lock:
            pending = self.pending_for(user)
        if pending is None or pending.directive not in (CONFIRM_SLOT, CONFIRM_INTENT):
            return None
        status = confirmation_of(
            strip_invocation(self.model.invocation_name, utterance), self.locale
        )
        if status is None:
            return None
        return pending.understanding if status == "CONFIRMED" else Understanding("AMAZON.NoIntent")

    def end_session(self, user: str | None = None) -> Turn | None:
        """End `user`'s open session (the Echo's own account's by default) as the user
        walking away would (reason USER_INITIATED)."""
        with self._lock:
            self._user, self._person = self._account(user), None
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

    def _new_session(self) -> _Session:
        """A fresh session, holding the speaker's last command while it may be corrected."""
        session = _Session()
        recent = self._recent.get((self._user, speaker(self._origin)))
        if recent is not None and self._clock() - recent[0] <= CORRECTION_WINDOW_S:
            session.attributes[LAST_COMMAND_ATTRIBUTE] = recent[1]
        return session

    def _say(self, utterance: str, given: Understanding | None = None) -> Turn:
        text = normalize_utterance(utterance)
        if not text and given is None:
            return self._silence(utterance)
        opening = self._open.match(text)
        if opening:
            self._session = self._new_session()
            return self._send(utterance, envelope.launch_request(), None)
        one_shot = self._one_shot.match(text)
        if one_shot:
            rest = one_shot["rest"] or ""
            # Invoking the skill again starts a new session, as it does on an Echo.
            self._session = self._new_session()
            if not rest and given is None:
                return self._send(utterance, envelope.launch_request(), None)
            text = rest
        elif text.startswith("alexa "):
            text = text.removeprefix("alexa ")
        if self._session is not None and text in self._exits:
            return self._send(utterance, envelope.session_ended_request(), None)
        if self._session is None:
            # A bare utterance with no session: treat it as addressed to this skill, as the
            # developer console's simulator does once the skill is selected.
            self._session = self._new_session()
        pending, self._session.pending = self._session.pending, None
        request, understanding = self._request(text, pending, given)
        answered = request.intent.confirmation_status.value != "NONE"
        if understanding.needs_confirmation and not answered:
            return self._confirm(self._session, utterance, understanding)
        return self._send(utterance, request, understanding)

    def _confirm(self, session: _Session, utterance: str, understanding: Understanding) -> Turn:
        """Ask the person to confirm a reading too unsure to act on; nothing is sent yet."""
        slot_types = self.model.intent_slots.get(understanding.intent, {})
        prompt = confirmation_prompt(understanding, slot_types, self.locale)
        session.pending = PendingDialog(understanding, CONFIRM_INTENT, None, prompt)
        return Turn(
            utterance=utterance,
            speech=prompt,
            intent=understanding.intent,
            slots=_slots_said(understanding),
            commands=[],
            latency_ms=0.0,
            session_open=True,
            request_type=CONFIRM_INTENT,
            reprompt=prompt,
        )

    def _request(
        self, text: str, pending: PendingDialog | None, given: Understanding | None
    ) -> tuple[Any, Understanding]:
        """The IntentRequest for `text`, read as the answer to `pending` when it is one."""
        if pending is not None and pending.directive in (CONFIRM_SLOT, CONFIRM_INTENT):
            status = confirmation_of(text, self.locale)
            if status is not None:
                so_far = pending.understanding
                if pending.directive == CONFIRM_INTENT:
                    request = envelope.intent_request(
                        self.identity, so_far, "IN_PROGRESS", intent_confirmation=status
                    )
                else:
                    confirmations = {str(pending.slot): status}
                    request = envelope.intent_request(
                        self.identity, so_far, "IN_PROGRESS", slot_confirmations=confirmations
                    )
                return request, so_far
            pending = None
        if given is not None:
            understanding = given
            if pending is not None and given.intent == pending.understanding.intent:
                slots = {**pending.understanding.slots, **given.slots}
                understanding = replace(given, slots=slots)
        elif len(text.split()) > self._longest_words:
            understanding = Understanding(FALLBACK_INTENT, confidence=1.0)
        elif pending is not None and pending.slot is not None:
            understanding = self._answer(text, pending.understanding, pending.slot)
        else:
            understanding = self.model.understand(text)
        same = pending is not None and understanding.intent == pending.understanding.intent
        state = "IN_PROGRESS" if same else "STARTED"
        return envelope.intent_request(self.identity, understanding, state), understanding

    def _answer(self, text: str, so_far: Understanding, slot_name: str) -> Understanding:
        """`text` as the answer to the question for `slot_name` of the intent `so_far`."""
        # An answer to "which zone?" is the slot value alone (or wrapped in a few words).
        value = self.model.answer(text, so_far.intent, slot_name)
        understanding = self.model.understand(text)
        same = understanding.intent == so_far.intent
        if value is None and not same:
            return understanding
        # As on Alexa, values the answer carries replace the intent's: "robot two please go
        # to zone a" answering "which robot?" for zone D is robot two to zone A.
        slots = {**so_far.slots, **({slot_name: value} if value else {})}
        if same:
            slots.update(understanding.slots)
        return replace(so_far, slots=slots)

    def _silence(self, utterance: str) -> Turn:
        """Nothing was said: the device says so and the session, if any, stays as it was."""
        return Turn(
            utterance=utterance,
            speech=SILENCE,
            intent=None,
            slots={},
            commands=[],
            latency_ms=0.0,
            session_open=self._session is not None,
            request_type="Silence",
        )

    def _send(self, utterance: str, request: Any, understanding: Understanding | None) -> Turn:
        session = self._session or _Session()
        event = envelope.envelope(
            self.identity,
            request,
            session_id=session.id,
            new=session.turns == 0,
            attributes=session.attributes,
            user_id=self._user,
            person_id=self._person,
        )
        event["request"]["locale"] = self.locale
        self._command_log()  # forget commands published outside this turn
        source = RequestSource(channel_of(self._origin), utterance.strip() or None)
        started = time.perf_counter()
        response = self.handler(event, source)
        latency_ms = (time.perf_counter() - started) * 1000
        commands = self._command_log()
        body = response.get("response", {})
        ended = request.object_type == "SessionEndedRequest" or body.get("shouldEndSession", True)
        attributes = response.get("sessionAttributes") or {}
        if LAST_COMMAND_ATTRIBUTE in attributes:
            self._recent[(self._user, speaker(self._origin))] = (
                self._clock(),
                attributes[LAST_COMMAND_ATTRIBUTE],
            )
        if ended:
            self._session = None
        else:
            session.turns += 1
            session.attributes = attributes
            session.pending = _pending(body, understanding, self.model)
        slots = _slots_said(understanding) if understanding else {}
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


def _slots_said(understanding: Understanding) -> dict[str, dict[str, str | None]]:
    return {
        name: {"value": value.spoken, "id": value.id} for name, value in understanding.slots.items()
    }


def _pending(
    body: dict[str, Any], understanding: Understanding | None, model: InteractionModel
) -> PendingDialog | None:
    """What a Dialog directive in the response asks, with the intent its updatedIntent keeps
    (a value the skill cleared, or changed, is dropped)."""
    for directive in body.get("directives") or []:
        kind = directive.get("type")
        if kind not in (ELICIT, CONFIRM_SLOT, CONFIRM_INTENT) or understanding is None:
            continue
        updated = directive.get("updatedIntent") or {}
        if updated.get("name", understanding.intent) != understanding.intent:
            continue
        updated_slots = updated.get("slots") or {}
        kept = {
            name: value
            for name, value in understanding.slots.items()
            if (updated_slots.get(name) or {}).get("value") == value.spoken
        }
        # A value the skill filled in itself ("Placebot two instead?") is said back to it
        # as the words of that value's name.
        for name, slot in updated_slots.items():
            said = (slot or {}).get("value")
            if said and name not in kept:
                value = model.answer(str(said), understanding.intent, name)
                if value is not None:
                    kept[name] = value
        so_far = Understanding(understanding.intent, kept, understanding.declared, None)
        slot = directive.get("slotToElicit") or directive.get("slotToConfirm")
        reprompt = speech_text((body.get("reprompt") or {}).get("outputSpeech")) or None
        return PendingDialog(so_far, str(kind), str(slot) if slot else None, reprompt)
    return None


class SimulatorAssistant:
    """The Alexa simulator in this process, as an `Assistant` (`vahr.plumbing.client`)."""

    def __init__(self, simulator: AlexaSimulator) -> None:
        self.simulator = simulator

    def ask(
        self,
        utterance: str,
        *,
        origin: str = "say",
        heard: dict[str, Any] | None = None,
        user: str | None = None,
    ) -> dict[str, Any]:
        turn = self.simulator.say(utterance, origin=origin, heard=heard, user=user)
        return {**turn.to_json(), "utterance": utterance}
