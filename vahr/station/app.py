"""The station's API, apart from HTTP: each route validates its request and answers.

Routes (all JSON unless said otherwise; errors are `{"error": "one line"}`):

| route | does |
| --- | --- |
| `GET /api/health` | `{"ok": true}` |
| `GET /api/snapshot` | what a page starts from (the fleet, robots, conversation, session) |
| `POST /api/command` `{"robot", "action": "navigate"|"stop", "zone"}` | one order from the panel |
| `POST /api/stop` `{}` | stop every robot (one message on the fleet topic) |
| `POST /api/say` `{"utterance", "origin"}` | a typed request (or the weather button) |
| `POST /api/voice` (a WAV file) | push-to-talk: transcript, the assistant's reply |
| `POST /api/speech` `{"text"}` | the text spoken by espeak-ng, as a WAV file |
| `POST /api/interaction`, `POST /api/puzzle` | the participant's input, for the session's log |
| `POST /api/acknowledge` `{"id"}` | an alert acknowledged: `{"acknowledged": [ids]}` |
| `POST /api/zone` `{"zone", "closed"}` | a zone closed or opened: the dispatcher's `ZoneChange` |
| `GET /api/map.png` | the map, when the fleet's floor is one (`floor_picture.py`) |
| `GET /api/me` | who works this page: `{"id", "name", "role", "may": [kinds], "signed_in"}` |

Every request is someone's (`vahr.domain.people.Person`): the person signed in, or, where
nobody signs in, anyone as a supervisor (`controls.ANYONE`). The panel's orders (a zone
closed or opened among them) are checked against their role and recorded with them; what
they type or say goes to the assistant as their Alexa account, so the skill decides and
records it the same way.

Each JSON body is decoded by msgspec into its route's request type (`json_routes`); an
empty body is `{}`, unknown fields are ignored, and an error names the field. The page
itself, its files and the event stream are the server's (`server.py`).
"""

from __future__ import annotations

import json
import logging
import re
from dataclasses import dataclass
from typing import TYPE_CHECKING, Annotated, Any

import msgspec

from vahr.domain.people import ACTION_KINDS, may
from vahr.errors import VahrError
from vahr.experiment.procedures import ProcedureViolation
from vahr.protocol import ProtocolError
from vahr.protocol.errors import from_validation_error
from vahr.speech.errors import SpeechError
from vahr.station.controls import ANYONE
from vahr.station.errors import RequestError

if TYPE_CHECKING:
    from collections.abc import Callable

    from vahr.domain.people import Person
    from vahr.plumbing.client import Assistant
    from vahr.station.controls import Controls
    from vahr.station.desk import Desk
    from vahr.station.feed import Feed
    from vahr.station.task_queue import ZoneSwitch
    from vahr.station.voice import PushToTalk

log = logging.getLogger(__name__)

MAX_UTTERANCE_CHARS = 300
MAX_SPEECH_CHARS = 1_000
# Who may speak through /api/say: typing in the conversation, the weather button.
SAY_ORIGINS = frozenset({"station", "station-weather"})

# msgspec's reason for a string over its length.
_TOO_LONG = re.compile(r"^expected `str` of length <= (\d+)$")

# The request bodies' fields, with the lengths the routes accept.
RobotName = Annotated[str, msgspec.Meta(max_length=128)]
Word = Annotated[str, msgspec.Meta(max_length=32)]
Utterance = Annotated[str, msgspec.Meta(max_length=MAX_UTTERANCE_CHARS)]
SpeechText = Annotated[str, msgspec.Meta(max_length=MAX_SPEECH_CHARS)]
AlertId = Annotated[str, msgspec.Meta(max_length=100)]


class CommandRequest(msgspec.Struct, frozen=True):
    """`POST /api/command`: one order from the panel (`zone` with `navigate`)."""

    robot: RobotName
    action: Word
    zone: Word | None = None


class StopRequest(msgspec.Struct, frozen=True):
    """`POST /api/stop`: no fields."""


class SayRequest(msgspec.Struct, frozen=True):
    """`POST /api/say`: a typed request, or the weather button's (`origin`)."""

    utterance: Utterance
    origin: Word = "station"


class SpeechRequest(msgspec.Struct, frozen=True):
    """`POST /api/speech`: text for espeak-ng to say."""

    text: SpeechText


class AcknowledgeRequest(msgspec.Struct, frozen=True):
    """`POST /api/acknowledge`: the alert acknowledged."""

    id: AlertId


class ZoneRequest(msgspec.Struct, frozen=True):
    """`POST /api/zone`: close (`closed: true`) or open a zone."""

    zone: Word
    closed: bool


# The participant's input: its own message types check it (`Desk.forward`).
ParticipantRequest = dict[str, Any]


@dataclass(frozen=True)
class JsonRoute:
    """A POST of JSON: the type its body is decoded into, and what answers it (given the
    person who sent it)."""

    shape: Any
    answer: Callable[[Any, Person], Reply]


@dataclass(frozen=True)
class Reply:
    status: int
    body: bytes
    content_type: str = "application/json"


def json_reply(body: object, status: int = 200) -> Reply:
    return Reply(status, json.dumps(body, separators=(",", ":")).encode())


def error_reply(status: int, message: str) -> Reply:
    return json_reply({"error": message}, status)


class StationApp:
    """The station's routes over its parts; `handle_json` and `voice` never raise."""

    def __init__(
        self,
        *,
        feed: Feed,
        controls: Controls,
        desk: Desk,
        assistant: Assistant | None,
        push_to_talk: PushToTalk | None,
        synthesize: Callable[[str], bytes] | None,
        zones: ZoneSwitch | None = None,
    ) -> None:
        self.feed = feed
        self.zones = zones
        self.controls = controls
        self.desk = desk
        self.assistant = assistant
        self.push_to_talk = push_to_talk
        self.synthesize = synthesize
        # Every POST of JSON the station answers: its path, its body's type, its answer.
        self.json_routes: dict[str, JsonRoute] = {
            "/api/command": JsonRoute(CommandRequest, self.command),
            "/api/stop": JsonRoute(StopRequest, self.stop_all),
            "/api/say": JsonRoute(SayRequest, self.say),
            "/api/speech": JsonRoute(SpeechRequest, self.speech),
            "/api/interaction": JsonRoute(ParticipantRequest, self.interaction),
            "/api/puzzle": JsonRoute(ParticipantRequest, self.puzzle),
            "/api/acknowledge": JsonRoute(AcknowledgeRequest, self.acknowledge),
            "/api/zone": JsonRoute(ZoneRequest, self.zone),
        }

    def handle_json(self, method: str, path: str, body: bytes, operator: Person = ANYONE) -> Reply:
        """A JSON route: the body decoded into the route's request type, then answered for
        `operator`."""
        route = self.json_routes.get(path) if method == "POST" else None
        if route is None:
            return error_reply(404, f"nothing to {method} at {path}")
        try:
            return route.answer(_decode(body, route.shape), operator)
        except RequestError as err:
            return error_reply(err.status, err.message)
        except ProcedureViolation as err:
            return error_reply(409, str(err))
        except ProtocolError as err:
            return error_reply(400, str(err))
        except VahrError as err:
            return error_reply(503, str(err))
        except Exception:  # the station must answer even when a bug bites
            log.exception("station request %s %s failed", method, path)
            return error_reply(500, "the station failed to handle the request; see its log")

    # -- routes -------------------------------------------------------------------------

    def me(self, operator: Person) -> Reply:
        """Who works this page and what they may do (the page hides what they may not)."""
        return json_reply(
            {
                "id": operator.id,
                "name": operator.name,
                "role": operator.role,
                "may": [kind for kind in ACTION_KINDS if may(operator.role, kind)],
                "signed_in": operator.known,
            }
        )

    def command(self, request: CommandRequest, operator: Person) -> Reply:
        if request.action == "navigate":
            if request.zone is None:
                raise RequestError(400, "zone: a string is required")
            command_id = self.controls.navigate(request.robot, request.zone, operator)
        elif request.action == "stop":
            command_id = self.controls.stop(request.robot, operator)
        else:
            raise RequestError(
                400, f"action: {request.action!r} is not one the panel sends (navigate or stop)"
            )
        return json_reply({"id": command_id})

    def stop_all(self, request: StopRequest, operator: Person) -> Reply:
        return json_reply({"id": self.controls.stop(None, operator)})

    def say(self, request: SayRequest, operator: Person) -> Reply:
        utterance = request.utterance.strip()
        if not utterance:
            raise RequestError(400, "utterance: say something (it is empty)")
        if request.origin not in SAY_ORIGINS:
            raise RequestError(400, f"origin: one of {', '.join(sorted(SAY_ORIGINS))}")
        if self.assistant is None:
            raise RequestError(503, "no assistant is connected to this station")
        return json_reply(
            self.assistant.ask(utterance, origin=request.origin, user=account(operator))
        )

    def speech(self, request: SpeechRequest, operator: Person) -> Reply:
        text = request.text.strip()
        if not text:
            raise RequestError(400, "text: nothing to say (it is empty)")
        if self.synthesize is None:
            raise RequestError(503, "espeak-ng is not installed on the station's computer")
        try:
            return Reply(200, self.synthesize(text), "audio/wav")
        except SpeechError as err:
            raise RequestError(503, str(err)) from err

    def interaction(self, request: ParticipantRequest, operator: Person) -> Reply:
        return self._participant("interaction", request)

    def puzzle(self, request: ParticipantRequest, operator: Person) -> Reply:
        return self._participant("puzzle", request)

    def _participant(self, kind: str, request: ParticipantRequest) -> Reply:
        logged = self.desk.forward(kind, request)
        return json_reply({"logged": logged}, 202 if logged else 200)

    def acknowledge(self, request: AcknowledgeRequest, operator: Person) -> Reply:
        """An alert acknowledged on a page: no page shows it from now on."""
        return json_reply({"acknowledged": self.feed.acknowledge(request.id)})

    def zone(self, request: ZoneRequest, operator: Person) -> Reply:
        """Close or open a zone at the dispatcher (no robot is sent into a closed one): a
        change to the whole fleet's service, so a supervisor's, and recorded."""
        if request.zone not in self.feed.fleet.zone_ids:
            zones = ", ".join(self.feed.fleet.zone_ids)
            raise RequestError(400, f"zone: {request.zone!r} is not a zone; zones are {zones}")
        if self.zones is None:
            raise RequestError(503, "closing a zone needs the fleet dispatcher, which is not here")
        switch = self.zones
        change = self.controls.change_zone(
            request.zone,
            request.closed,
            operator,
            lambda: switch.set(request.zone, closed=request.closed),
        )
        return json_reply(change)

    def voice(self, wav: bytes, operator: Person = ANYONE) -> Reply:
        """Push-to-talk: a WAV clip in, what was heard and answered out (spoken as the
        operator's Alexa account)."""
        if self.push_to_talk is None:
            return error_reply(503, "push-to-talk needs an assistant and a recognizer")
        try:
            return json_reply(self.push_to_talk.handle(wav, user=account(operator)))
        except RequestError as err:
            return error_reply(err.status, err.message)
        except (SpeechError, VahrError) as err:
            return error_reply(503, str(err))
        except Exception:
            log.exception("push-to-talk failed")
            return error_reply(500, "push-to-talk failed; see the station's log")


def account(operator: Person) -> str | None:
    """The Alexa account the operator speaks to the assistant as: their own when they signed
    in, else the assistant's own (everyone at an open station is one speaker, as before)."""
    return operator.id if operator.known else None


def _decode(body: bytes, shape: Any) -> Any:
    """The body as `shape` (an empty body is `{}`); an error names the field, in the words
    the page has always shown (every field of these requests is a string)."""
    try:
        return msgspec.json.decode(body or b"{}", type=shape)
    except msgspec.ValidationError as err:  # before DecodeError, its base class
        error = from_validation_error(err)
        if error.field == "payload":
            raise RequestError(400, "the body must be a JSON object") from None
        if too_long := _TOO_LONG.match(error.reason):
            raise RequestError(400, f"{error.field}: at most {too_long[1]} characters") from None
        if error.reason == "is required but missing" or error.reason.startswith("expected str"):
            raise RequestError(400, f"{error.field}: a string is required") from None
        raise error from err
    except msgspec.DecodeError:
        raise RequestError(400, "the body is not valid JSON") from None
