"""The port through which a simulated participant speaks to the assistant, and its adapter.

The adapter runs `vahr say UTTERANCE --api URL --json`, the command-line contract of the
local stack (DESIGN.md), so the participant talks to the running system exactly as a
person at the terminal would, through the Alexa simulator and the real skill.
"""

from __future__ import annotations

import json
import subprocess
import sys
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
        return AssistantReply(
            speech=str(body.get("speech") or ""),
            intent=body.get("intent"),
            commands=[str(c) for c in body.get("commands") or []],
        )
