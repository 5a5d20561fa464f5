"""A small client of a running `vahr up`: say an utterance, read the meter (stdlib only,
so `vahr say` starts fast)."""

from __future__ import annotations

import json
import os
import time
import urllib.error
import urllib.request
from typing import Any

from vahr.errors import VahrError

DEFAULT_API = "http://127.0.0.1:8180"
TIMEOUT_S = 15.0  # more than Alexa's 8 s, so the skill's own timeout is what shows


def default_api() -> str:
    return os.environ.get("VAHR_API", DEFAULT_API)


def call(api: str, method: str, path: str, body: dict[str, Any] | None = None) -> dict[str, Any]:
    data = json.dumps(body).encode() if body is not None else None
    request = urllib.request.Request(
        f"{api.rstrip('/')}{path}",
        data=data,
        method=method,
        headers={"Content-Type": "application/json"},
    )
    try:
        with urllib.request.urlopen(request, timeout=TIMEOUT_S) as response:
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
        raise VahrError(
            f"nothing answers at {api} ({reason}); start the system with `vahr up`"
        ) from err


def say(api: str, utterance: str) -> dict[str, Any]:
    """The turn's JSON, with `latency_ms` measured here: utterance in to reply out."""
    started = time.perf_counter()
    turn = call(api, "POST", "/vahr/say", {"utterance": utterance})
    turn["skill_ms"] = turn.get("latency_ms")
    turn["latency_ms"] = round((time.perf_counter() - started) * 1000, 1)
    return turn
