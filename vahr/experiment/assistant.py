"""The port through which a simulated participant speaks to the assistant, and its adapters.

- `HttpAssistant` posts the utterance to the local stack's `POST /vahr/say` (the Alexa
  simulator in front of the real skill), as `vahr say` does, without starting a process,
  so the assistant's own latency is all that is measured.
- `SayCommandAssistant` runs `vahr say UTTERANCE --json`, the command-line contract
  (DESIGN.md), for a system reachable only that way.
"""

from __future__ import annotations

import json
import subprocess
import sys
import urllib.error
import urllib.request
from dataclasses import dataclass, field
from typing import Protocol

SAY_TIMEOUT_S = 15.0


@dataclass(frozen=True)
class AssistantReply:
    speech: str
    intent: str | None = None
    commands: list[str] = field(default_factory=list)
    error: str | None = None


class Assistant(Protocol):
    def ask(self, utterance: str) -> AssistantReply:
        """Say `utterance` to the assistant; return what it answered and the commands sent."""


def _reply(body: dict[str, object]) -> AssistantReply:
    commands = body.get("commands") or []
    return AssistantReply(
        speech=str(body.get("speech") or ""),
        intent=str(body["intent"]) if body.get("intent") else None,
        commands=[str(c) for c in commands] if isinstance(commands, list) else [],
    )


class HttpAssistant:
    """Speaks through the local stack's `POST /vahr/say` (`vahr up`'s `api` URL)."""

    def __init__(self, api_url: str, timeout_s: float = SAY_TIMEOUT_S) -> None:
        self.url = api_url.rstrip("/") + "/vahr/say"
        self.timeout_s = timeout_s

    def ask(self, utterance: str) -> AssistantReply:
        request = urllib.request.Request(
            self.url,
            data=json.dumps({"utterance": utterance}).encode(),
            headers={"Content-Type": "application/json"},
            method="POST",
        )
        try:
            with urllib.request.urlopen(request, timeout=self.timeout_s) as response:
                body = json.loads(response.read() or b"{}")
        except urllib.error.HTTPError as err:
            detail = err.read().decode("utf-8", "replace")[:200]
            return AssistantReply("", error=f"the assistant answered HTTP {err.code}: {detail}")
        except (urllib.error.URLError, TimeoutError, OSError) as err:
            return AssistantReply("", error=f"the assistant at {self.url} is unreachable: {err}")
        except json.JSONDecodeError:
            return AssistantReply("", error="the assistant's answer is not JSON")
        return _reply(body if isinstance(body, dict) else {})


class SayCommandAssistant:
    """Speaks through `vahr say --json` against the local stack's API."""

    def __init__(self, api_url: str | None) -> None:
        self.api_url = api_url

    def ask(self, utterance: str) -> AssistantReply:
        argv = [sys.executable, "-m", "vahr.cli", "say", utterance, "--json"]
        if self.api_url:
            argv += ["--api", self.api_url]
        try:
            done = subprocess.run(
                argv, capture_output=True, text=True, timeout=SAY_TIMEOUT_S, check=False
            )
        except subprocess.TimeoutExpired:
            return AssistantReply(
                "", error=f"the assistant did not answer in {SAY_TIMEOUT_S:.0f} s"
            )
        if done.returncode != 0:
            reason = (done.stderr.strip().splitlines() or [f"exit {done.returncode}"])[-1]
            return AssistantReply("", error=reason)
        try:
            body = json.loads(done.stdout.strip().splitlines()[-1])
        except (json.JSONDecodeError, IndexError):
            return AssistantReply("", error="vahr say printed no JSON")
        return _reply(body if isinstance(body, dict) else {})
