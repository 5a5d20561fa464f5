"""Who may do what, asked before anything moves: each request's `Access`, the refusal, the
confirmation of fleet-wide commands, and the request's record in the audit trail.

- `AccessInterceptor` (a request interceptor) classifies the request from its intent and
  slots (`skill.access.classify`), looks the speaker up (`skill.speakers`) and decides
  whether their role allows it (`vahr.domain.people.may`). A stop needs nobody's role and
  a question anybody's, so only commands wait for the directory.
- `RefusedRequestHandler`, first of the handlers, answers a request the role does not
  allow: it says what the person may do and sends nothing.
- `confirm_first`, called by the step that sends (`skill.handlers.send`, the fleet
  handlers), asks "... is that right?" (Dialog.ConfirmIntent) before a fleet-wide command
  when confirmation is on, and notes who was asked in the session. Only that person's yes
  carries it out: a yes from anyone else, a no, anything else said, or the session ending
  sends nothing.
- `TrailInterceptor` (a response interceptor) writes one record of what the request did
  (`skill.deeds`) to the trail (`skill.trail`); `record_failure` does it for a request that
  ended in the catch-all exception handler.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import msgspec
from ask_sdk_core.dispatch_components import (
    AbstractRequestHandler,
    AbstractRequestInterceptor,
    AbstractResponseInterceptor,
)
from ask_sdk_model import IntentRequest

from skill import deeds, prompts
from skill.access import INTENT_RULES, REQUEST_KINDS, classify
from skill.errors import PeopleUnavailable
from skill.responses import answer, confirm_intent
from skill.slots import resolved_ids
from skill.speakers import speaker_id
from skill.trail import append_or_log
from skill.vocabulary import capitalise
from vahr.domain import FLEET_GROUP
from vahr.domain.invocation import FALLBACK_INTENT
from vahr.domain.people import CONFIRMED_KINDS, Person, may
from vahr.protocol.audit import AuditEntry, RequestSource, now

if TYPE_CHECKING:
    from ask_sdk_core.handler_input import HandlerInput
    from ask_sdk_model import Intent, Response, Slot

    from skill.runtime import SkillRuntime
    from vahr.domain.people import ActionKind
    from vahr.protocol.audit import Outcome

ACCESS = "access"
# The session attribute holding the fleet-wide command that waits for its asker's yes.
CONFIRMING = "confirming"
CONFIRMED, DENIED = "CONFIRMED", "DENIED"
KIND_WORDS: dict[str, str] = {
    "question": "questions",
    "command": "commands to robots",
    "fleet": "fleet-wide commands",
    "stop": "stops",
}
# Dialog directives after which the request goes on (a slot asked for): no record yet.
DIALOG_GOES_ON = ("Dialog.ElicitSlot", "Dialog.ConfirmSlot")


class Pending(msgspec.Struct, frozen=True):
    """A fleet-wide command asked about: whose, and what, for the record if it is dropped."""

    intent: str
    by: str
    name: str | None
    role: str
    slots: dict[str, str | None]
    words: str | None = None


class Access(msgspec.Struct):
    """What the guard decided about one request."""

    person: Person
    kind: ActionKind
    allowed: bool
    # A yes must come before anything is sent, and whether it came (from the asker).
    confirm: bool = False
    confirmed: bool = False
    # Someone answered yes to another person's question.
    not_theirs: bool = False


def access_of(handler_input: HandlerInput) -> Access | None:
    """The request's `Access`, or None before (or without) the interceptor."""
    manager = handler_input.attributes_manager
    found = manager.request_attributes.get(ACCESS) if manager is not None else None
    return found if isinstance(found, Access) else None


def source_of(handler_input: HandlerInput) -> RequestSource:
    """The channel and words, where the assistant in this process passed them."""
    context = handler_input.context
    return context if isinstance(context, RequestSource) else RequestSource()


def _session(handler_input: HandlerInput) -> dict[str, Any] | None:
    if handler_input.request_envelope.session is None:
        return None
    manager = handler_input.attributes_manager
    if manager.session_attributes is None:
        manager.session_attributes = {}
    attributes: dict[str, Any] | None = manager.session_attributes
    return attributes


def _pending(attributes: dict[str, Any] | None) -> Pending | None:
    stored = (attributes or {}).pop(CONFIRMING, None)
    if stored is None:
        return None
    try:
        return msgspec.convert(stored, Pending)
    except msgspec.ValidationError:
        return None  # attributes come back from the device: a damaged one asks nothing


class AccessInterceptor(AbstractRequestInterceptor):
    """Decide the request's `Access` before any handler sees it."""

    def __init__(self, runtime: SkillRuntime) -> None:
        self.runtime = runtime

    def process(self, handler_input: HandlerInput) -> None:
        deeds.begin()
        request = handler_input.request_envelope.request
        intent = request.intent if isinstance(request, IntentRequest) else None
        if intent is not None:
            kind = classify(intent, self.runtime.vocabulary, self.runtime.group_threshold)
        else:
            kind = REQUEST_KINDS.get(str(getattr(request, "object_type", "")), "question")
        person = self._person(speaker_id(handler_input.request_envelope), kind)
        access = Access(person=person, kind=kind, allowed=may(person.role, kind))
        access.confirm = self.runtime.confirmation and kind in CONFIRMED_KINDS
        status = _confirmation(intent)
        pending = _pending(_session(handler_input))
        if pending is not None:
            answers = intent is not None and intent.name == pending.intent and status != "NONE"
            if not answers:
                self._dropped(handler_input, pending, "not confirmed: something else was said")
            elif status == CONFIRMED and pending.by != person.id:
                access.not_theirs = True
                self._dropped(handler_input, pending, "someone else answered yes")
        if status == CONFIRMED and not access.not_theirs:
            access.confirmed = True
        if status == DENIED:
            access.allowed = True  # a no sends nothing, whoever says it
        handler_input.attributes_manager.request_attributes[ACCESS] = access

    def _person(self, person_id: str, kind: ActionKind) -> Person:
        """The speaker; for a question or a stop, which any role may ask, an unreadable
        directory only leaves their name out of the record."""
        try:
            return self.runtime.people.person(person_id)
        except PeopleUnavailable:
            if kind in ("question", "stop"):
                return Person(id=person_id, role="viewer")
            raise

    def _dropped(self, handler_input: HandlerInput, pending: Pending, reason: str) -> None:
        """The command asked about will not be carried out: its record says so."""
        source = source_of(handler_input)
        entry = AuditEntry(
            time=now(),
            who=pending.by,
            name=pending.name,
            role=pending.role,
            channel=source.channel,
            words=pending.words,
            intent=pending.intent,
            slots=pending.slots,
            outcome="cancelled",
            reason=reason,
        )
        append_or_log(self.runtime.trail, entry)


def _confirmation(intent: Intent | None) -> str:
    status = intent.confirmation_status if intent is not None else None
    return status.value if status is not None else "NONE"


class RefusedRequestHandler(AbstractRequestHandler):
    """A request the speaker's role does not allow, or a yes to someone else's question:
    say what they may do; send nothing."""

    def can_handle(self, handler_input: HandlerInput) -> bool:
        access = access_of(handler_input)
        return access is not None and (access.not_theirs or not access.allowed)

    def handle(self, handler_input: HandlerInput) -> Response:
        access = access_of(handler_input)
        assert access is not None
        if access.not_theirs:
            return answer(handler_input, prompts.NOT_YOURS_TO_CONFIRM)
        return answer(handler_input, refusal(access.person))


def refusal(person: Person) -> str:
    """What `person` may do, said when they asked for more; nothing was sent."""
    may_do = prompts.MAY[person.role]
    if person.known:
        role = prompts.ROLE_NAMES[person.role]
        return prompts.REFUSED_KNOWN.format(name=person.name, role=role, may=may_do)
    return prompts.REFUSED_UNKNOWN.format(may=may_do)


def confirm_first(handler_input: HandlerInput, runtime: SkillRuntime) -> Response | None:
    """Ask the speaker to confirm a fleet-wide command before it is sent (and remember whom
    we asked); None when it may be sent now."""
    access = access_of(handler_input)
    if access is None or not access.confirm or access.confirmed:
        return None
    request = handler_input.request_envelope.request
    intent = request.intent if isinstance(request, IntentRequest) else None
    if intent is None:
        return None
    attributes = _session(handler_input)
    if attributes is not None:
        pending = Pending(
            intent=str(intent.name),
            by=access.person.id,
            name=access.person.name,
            role=access.person.role,
            slots=slot_values(intent),
            words=source_of(handler_input).words,
        )
        attributes[CONFIRMING] = msgspec.to_builtins(pending)
    deeds.asked()
    return confirm_intent(handler_input, confirmation_question(intent, runtime))


def confirmation_question(intent: Intent, runtime: SkillRuntime) -> str:
    """ "Send all robots to zone a, is that right?": the intent's sentence with the names of
    what its slots resolved to."""
    vocabulary, fleet = runtime.vocabulary, runtime.fleet
    names: dict[str, str] = {}
    for name, slot in (intent.slots or {}).items():
        said = slot.value or ""
        resolved = _resolved(slot)
        if resolved == FLEET_GROUP:
            names[name] = prompts.EVERY_ROBOT
        elif resolved in vocabulary.robot_ids:
            names[name] = vocabulary.robot(resolved)
        elif resolved in fleet.zone_ids:
            names[name] = vocabulary.zone(resolved)
        else:
            names[name] = said
    group = next((g for g in fleet.groups if g.id == names.get("group")), None)
    if "group" in names and names["group"]:
        names["robots"] = group.spoken[0] if group is not None else names["group"]
    elif names.get("count"):
        names["robots"] = prompts.ROBOTS_COUNTED.format(count=names["count"])
    else:
        names["robots"] = prompts.EVERY_ROBOT
    template = prompts.CONFIRM_COMMAND.get(str(intent.name), prompts.CONFIRM_ANY)
    return capitalise(str(template).format_map(_Blank(names)))


class _Blank(dict[str, str]):
    def __missing__(self, key: str) -> str:
        return ""


def _resolved(slot: Slot) -> str | None:
    matched = resolved_ids(slot)
    return matched[0] if matched else None


def slot_values(intent: Intent) -> dict[str, str | None]:
    """Each slot that was said: the id it resolved to, else the words heard."""
    return {
        name: _resolved(slot) or slot.value
        for name, slot in (intent.slots or {}).items()
        if slot.value
    }


class TrailInterceptor(AbstractResponseInterceptor):
    """Write the request's record to the audit trail, once it has been answered."""

    def __init__(self, runtime: SkillRuntime) -> None:
        self.runtime = runtime

    def process(self, handler_input: HandlerInput, response: Response | None) -> None:
        entry = request_entry(handler_input, _outcome(handler_input, response))
        if entry is not None:
            append_or_log(self.runtime.trail, entry)


def record_failure(handler_input: HandlerInput, runtime: SkillRuntime, error: str) -> None:
    """The record of a request that failed with an exception (no response interceptor runs
    then)."""
    access = access_of(handler_input)
    if access is not None and access.kind == "question" and not _asked_a_question(handler_input):
        return
    deeds.failed(error)
    entry = request_entry(handler_input, "failed")
    if entry is not None:
        append_or_log(runtime.trail, entry)


def request_entry(handler_input: HandlerInput, outcome: Outcome | None) -> AuditEntry | None:
    """The record of this request with `outcome`; None when there is nothing to record."""
    if outcome is None:
        return None
    access = access_of(handler_input)
    request = handler_input.request_envelope.request
    intent = request.intent if isinstance(request, IntentRequest) else None
    person = access.person if access is not None else None
    done = deeds.current()
    source = source_of(handler_input)
    reason = done.failure
    if outcome == "refused" and access is not None:
        reason = (
            "a yes to someone else's command"
            if access.not_theirs
            else f"the {access.person.role} role does not allow {KIND_WORDS[access.kind]}"
        )
    return AuditEntry(
        time=now(),
        who=person.id if person else speaker_id(handler_input.request_envelope),
        name=person.name if person else None,
        role=person.role if person else None,
        channel=source.channel,
        words=source.words,
        intent=intent.name if intent is not None else None,
        slots=slot_values(intent) if intent is not None else {},
        robots=list(done.robots),
        commands=list(done.commands),
        outcome=outcome,
        reason=reason,
    )


def _asked_a_question(handler_input: HandlerInput) -> bool:
    """A question about the robots (not the conversation's own: help, goodbye, fallback)."""
    request = handler_input.request_envelope.request
    if not isinstance(request, IntentRequest) or request.intent is None:
        return False
    name = request.intent.name
    return (
        name in INTENT_RULES
        and INTENT_RULES[name].kind == "question"
        and not name.startswith("AMAZON.")
        and name != FALLBACK_INTENT
    )


def _outcome(handler_input: HandlerInput, response: Response | None) -> Outcome | None:
    """What became of the request, for its record; None when it is not recorded (the
    conversation's own turns, a dialog still asking for a slot)."""
    access = access_of(handler_input)
    if access is None:
        return None
    done = deeds.current()
    request = handler_input.request_envelope.request
    intent = request.intent if isinstance(request, IntentRequest) else None
    status = _confirmation(intent)
    if access.not_theirs or not access.allowed:
        return "refused"
    if done.failure is not None:
        return "failed"
    if done.asked:
        return "asked"
    if status == DENIED and access.kind != "question":
        return "cancelled"
    if done.sent:
        return "confirmed" if status == CONFIRMED else "sent"
    if access.kind == "question":
        return "answered" if _asked_a_question(handler_input) else None
    directives = (response.directives or []) if response is not None else []
    if any(getattr(d, "object_type", None) in DIALOG_GOES_ON for d in directives):
        return None
    return "unsent" if intent is not None else None
