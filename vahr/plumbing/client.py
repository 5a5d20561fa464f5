"""How a caller speaks to the assistant, and a small client of a running `vahr up` (stdlib
only, so `vahr say` starts fast).

`Assistant` is the one port through which the station, the experiment's simulated
participant and the demo speak to the assistant. Every adapter returns the turn as `vahr say
--json` prints it, with the utterance, and raises `VahrError` when the assistant cannot be
reached or gives no turn:

- `HttpAssistant` posts to a running local stack's `POST /vahr/say` (the Alexa simulator
  in front of the real skill), as `vahr say` does, without starting a process;
- `vahr.assistant.SimulatorAssistant` calls an `AlexaSimulator` in this process (`vahr up`'s
  own, or one the station builds around the skill for a deployment on AWS IoT Core);
- `SayCommandAssistant` runs `vahr say UTTERANCE --json`, the command-line contract
  (docs/protocol.md, The command line), for a system reachable only that way.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import time
import urllib.error
import urllib.request
from typing import Any, Protocol

from vahr.errors import VahrError

DEFAULT_API = "http://127.0.0.1:8180"
TIMEOUT_S = 15.0  # more than Alexa's 8 s, so the skill's own timeout is what shows
# How long `vahr say` waits for its answer. It tells the stack (`timeout_s`), which starts
# the turn only while it can still answer in time and sends no command after it: a say
# that fails here is never carried out later (vahr.assistant.deadline).
SAY_TIMEOUT_S = 30.0
SAY_PATH = "/vahr/say"

# One exchange as `vahr say --json` prints it ("speech", "intent", "slots", "commands",
# "latency_ms", "session_open", "request_type", "reprompt", "origin", "heard"), with the
# "utterance" said.
Turn = dict[str, Any]


class NoAnswerInTime(VahrError):
    """The server took the request and gave no answer within the caller's timeout."""


def default_api() -> str:
    return os.environ.get("VAHR_API", DEFAULT_API)


def call(
    api: str,
    method: str,
    path: str,
    body: dict[str, Any] | None = None,
    *,
    timeout_s: float = TIMEOUT_S,
) -> dict[str, Any]:
    data = json.dumps(body).encode() if body is not None else None
    request = urllib.request.Request(
        f"{api.rstrip('/')}{path}",
        data=data,
        method=method,
        headers={"Content-Type": "application/json"},
    )
    try:
        with urllib.request.urlopen(request, timeout=timeout_s) as response:
            answer: dict[str, Any] = json.loads(response.read() or b"{}")
            return answer
    except urllib.error.HTTPError as err:
        try:
            message = json.loads(err.read()).get("message", err.reason)
        except ValueError:
            message = err.reason
        raise VahrError(f"{api} answered {err.code}: {message}") from err
    except (urllib.error.URLError, TimeoutError, ConnectionError) as err:
        reason = getattr(err, "reason", err)
        if isinstance(reason, TimeoutError):
            # The server took the request but did not answer in time: it is there.
            raise NoAnswerInTime(
                f"{api} did not answer {method} {path} within {timeout_s:g} s"
            ) from err
        raise VahrError(
            f"nothing answers at {api} ({reason}); start the system with `vahr up`"
        ) from err
    except ValueError as err:
        raise VahrError(f"{api}{path} did not answer with JSON") from err


def say(
    api: str,
    utterance: str,
    locale: str | None = None,
    *,
    user: str | None = None,
    person: str | None = None,
) -> dict[str, Any]:
    """The turn's JSON, with `latency_ms` measured here: utterance in to reply out.
    `locale` is the language spoken; the system refuses one it was not started in. `user`
    speaks as that Alexa account (its userId), `person` as a voice Alexa recognised (its
    personId)."""
    started = time.perf_counter()
    body: dict[str, Any] = {"utterance": utterance, "timeout_s": SAY_TIMEOUT_S}
    for key, value in (("locale", locale), ("user", user), ("person", person)):
        if value is not None:
            body[key] = value
    turn = _say_call(api, body, SAY_TIMEOUT_S)
    turn["skill_ms"] = turn.get("latency_ms")
    turn["latency_ms"] = round((time.perf_counter() - started) * 1000, 1)
    return turn


def _say_call(api: str, body: dict[str, Any], timeout_s: float) -> dict[str, Any]:
    """`POST /vahr/say` waiting `timeout_s` (which the body tells the stack). A stack that
    did not answer in time sends no command of this request after it, and the error says
    so."""
    try:
        return call(api, "POST", SAY_PATH, body, timeout_s=timeout_s)
    except NoAnswerInTime as err:
        raise NoAnswerInTime(
            f"{api} gave no answer within {timeout_s:g} s, so it sends no command for this "
            "request from now on; ask where the robots are before you say it again"
        ) from err


class Assistant(Protocol):
    def ask(
        self,
        utterance: str,
        *,
        origin: str = "say",
        heard: dict[str, Any] | None = None,
        user: str | None = None,
    ) -> Turn:
        """Say `utterance` to the assistant; `origin` names who spoke, `heard` what the
        recognizer made of it, `user` the Alexa account (userId) speaking, when not the
        assistant's own. Raises VahrError when the assistant cannot be reached."""
        ...


class HttpAssistant:
    """A running local stack's `POST /vahr/say` (`vahr up`'s `api` URL)."""

    def __init__(self, api_url: str, timeout_s: float = SAY_TIMEOUT_S) -> None:
        self.api_url = api_url
        self.timeout_s = timeout_s

    def ask(
        self,
        utterance: str,
        *,
        origin: str = "say",
        heard: dict[str, Any] | None = None,
        user: str | None = None,
    ) -> Turn:
        body: dict[str, Any] = {
            "utterance": utterance,
            "origin": origin,
            "timeout_s": self.timeout_s,
        }
        if heard is not None:
            body["heard"] = heard
        if user is not None:
            body["user"] = user
        turn = _say_call(self.api_url, body, self.timeout_s)
        return _with_utterance(turn, utterance, f"{self.api_url}{SAY_PATH}")


class SayCommandAssistant:
    """`vahr say --json` against the local stack's API (`origin` and `heard` are not passed
    on: the command speaks as "say"; `user` is, as `--user`)."""

    def __init__(self, api_url: str | None, timeout_s: float = SAY_TIMEOUT_S + 10.0) -> None:
        self.api_url = api_url
        self.timeout_s = timeout_s

    def ask(
        self,
        utterance: str,
        *,
        origin: str = "say",
        heard: dict[str, Any] | None = None,
        user: str | None = None,
    ) -> Turn:
        argv = [sys.executable, "-m", "vahr.cli", "say", utterance, "--json"]
        if self.api_url:
            argv += ["--api", self.api_url]
        if user is not None:
            argv += ["--user", user]
        try:
            done = subprocess.run(
                argv, capture_output=True, text=True, timeout=self.timeout_s, check=False
            )
        except subprocess.TimeoutExpired as err:
            raise VahrError(f"the assistant did not answer in {self.timeout_s:.0f} s") from err
        if done.returncode != 0:
            raise VahrError((done.stderr.strip().splitlines() or [f"exit {done.returncode}"])[-1])
        try:
            turn = json.loads(done.stdout.strip().splitlines()[-1])
        except (json.JSONDecodeError, IndexError) as err:
            raise VahrError("vahr say printed no JSON") from err
        return _with_utterance(turn, utterance, "vahr say")


def _with_utterance(turn: object, utterance: str, source: str) -> Turn:
    if not isinstance(turn, dict) or "speech" not in turn:
        raise VahrError(f"{source} did not answer with a turn")
    return {**turn, "utterance": utterance}
