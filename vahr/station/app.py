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

The page itself, its files and the event stream are the server's (`server.py`).
"""

from __future__ import annotations

import json
import logging
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from vahr.errors import VahrError
from vahr.experiment.procedures import ProcedureViolation
from vahr.protocol import ProtocolError
from vahr.speech.errors import SpeechError
from vahr.station.errors import RequestError

if TYPE_CHECKING:
    from collections.abc import Callable

    from vahr.local.client import Assistant
    from vahr.station.controls import Controls
    from vahr.station.desk import Desk
    from vahr.station.feed import Feed
    from vahr.station.voice import PushToTalk

log = logging.getLogger(__name__)

MAX_UTTERANCE_CHARS = 300
MAX_SPEECH_CHARS = 1_000
# Who may speak through /api/say: typing in the conversation, the weather button.
SAY_ORIGINS = frozenset({"station", "station-weather"})

Json = dict[str, Any]


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
    """The station's routes over its parts; `handle` never raises."""

    def __init__(
        self,
        *,
        feed: Feed,
        controls: Controls,
        desk: Desk,
        assistant: Assistant | None,
        push_to_talk: PushToTalk | None,
        synthesize: Callable[[str], bytes] | None,
    ) -> None:
        self.feed = feed
        self.controls = controls
        self.desk = desk
        self.assistant = assistant
        self.push_to_talk = push_to_talk
        self.synthesize = synthesize
        self._json_routes: dict[tuple[str, str], Callable[[Json], Reply]] = {
            ("POST", "/api/command"): self.command,
            ("POST", "/api/stop"): self.stop_all,
            ("POST", "/api/say"): self.say,
            ("POST", "/api/speech"): self.speech,
            ("POST", "/api/interaction"): lambda body: self.participant("interaction", body),
            ("POST", "/api/puzzle"): lambda body: self.participant("puzzle", body),
            ("POST", "/api/acknowledge"): self.acknowledge,
        }

    def is_json_route(self, method: str, path: str) -> bool:
        return (method, path) in self._json_routes

    def handle_json(self, method: str, path: str, body: bytes) -> Reply:
        """A JSON route: the body must be a JSON object."""
        try:
            try:
                request = json.loads(body or b"{}")
            except (ValueError, UnicodeDecodeError):
                raise RequestError(400, "the body is not valid JSON") from None
            if not isinstance(request, dict):
                raise RequestError(400, "the body must be a JSON object")
            return self._json_routes[(method, path)](request)
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

    def command(self, request: Json) -> Reply:
        robot = _text(request, "robot", 128)
        action = _text(request, "action", 32)
        if action == "navigate":
            command_id = self.controls.navigate(robot, _text(request, "zone", 32))
        elif action == "stop":
            command_id = self.controls.stop(robot)
        else:
            raise RequestError(
                400, f"action: {action!r} is not one the panel sends (navigate or stop)"
            )
        return json_reply({"id": command_id})

    def stop_all(self, request: Json) -> Reply:
        return json_reply({"id": self.controls.stop(None)})

    def say(self, request: Json) -> Reply:
        utterance = _text(request, "utterance", MAX_UTTERANCE_CHARS).strip()
        if not utterance:
            raise RequestError(400, "utterance: say something (it is empty)")
        origin = request.get("origin", "station")
        if origin not in SAY_ORIGINS:
            raise RequestError(400, f"origin: one of {', '.join(sorted(SAY_ORIGINS))}")
        if self.assistant is None:
            raise RequestError(503, "no assistant is connected to this station")
        return json_reply(self.assistant.ask(utterance, origin=origin))

    def speech(self, request: Json) -> Reply:
        text = _text(request, "text", MAX_SPEECH_CHARS).strip()
        if not text:
            raise RequestError(400, "text: nothing to say (it is empty)")
        if self.synthesize is None:
            raise RequestError(503, "espeak-ng is not installed on the station's computer")
        try:
            return Reply(200, self.synthesize(text), "audio/wav")
        except SpeechError as err:
            raise RequestError(503, str(err)) from err

    def participant(self, kind: str, request: Json) -> Reply:
        logged = self.desk.forward(kind, request)
        return json_reply({"logged": logged}, 202 if logged else 200)

    def acknowledge(self, request: Json) -> Reply:
        """An alert acknowledged on a page: no page shows it from now on."""
        return json_reply({"acknowledged": self.feed.acknowledge(_text(request, "id", 100))})

    def voice(self, wav: bytes) -> Reply:
        """Push-to-talk: a WAV clip in, what was heard and answered out."""
        if self.push_to_talk is None:
            return error_reply(503, "push-to-talk needs an assistant and a recognizer")
        try:
            return json_reply(self.push_to_talk.handle(wav))
        except RequestError as err:
            return error_reply(err.status, err.message)
        except (SpeechError, VahrError) as err:
            return error_reply(503, str(err))
        except Exception:
            log.exception("push-to-talk failed")
            return error_reply(500, "push-to-talk failed; see the station's log")


def _text(request: Json, field: str, limit: int) -> str:
    value = request.get(field)
    if not isinstance(value, str):
        raise RequestError(400, f"{field}: a string is required")
    if len(value) > limit:
        raise RequestError(400, f"{field}: at most {limit} characters")
    return value
