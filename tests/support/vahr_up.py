"""`vahr up --json` as a background process for end-to-end tests, and `vahr say` against it.

`start_up(state_dir, ...)` runs the real command line on free loopback ports and returns an
`Up` once its first line (the endpoints) is printed; every later line (one robot event each)
is queued. `stop_up` ends it with SIGTERM.
"""

from __future__ import annotations

import json
import os
import queue
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path
from typing import IO, Any

from vahr.plumbing.lifetime import spawn
from vahr.plumbing.ports import free_port

ROOT = Path(__file__).resolve().parents[2]
VAHR = [sys.executable, "-m", "vahr.cli"]
START_TIMEOUT_S = 60.0
# The stacks the running test started itself: a failed test's report shows each one's story
# beside the stacks it got from fixtures (tests/conftest.py).
started: list[Up] = []


def clean_env() -> dict[str, str]:
    """The environment for the commands: this checkout on the path, no AWS identity."""
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    for name in ("AWS_ACCESS_KEY_ID", "AWS_SECRET_ACCESS_KEY", "AWS_PROFILE", "VAHR_API"):
        env.pop(name, None)
    return env


class Up:
    """A `vahr up --json` process and the JSON lines it prints."""

    def __init__(
        self, process: subprocess.Popen[str], endpoints: dict[str, Any], log: Path | None = None
    ) -> None:
        self.process = process
        self.endpoints = endpoints
        # Where its stderr goes (`story`).
        self.log = log
        self.lines: queue.Queue[dict[str, Any]] = queue.Queue()
        self._reader = threading.Thread(target=self._read, args=(process.stdout,), daemon=True)
        self._reader.start()

    def _read(self, stream: IO[str]) -> None:
        for line in stream:
            self.lines.put(json.loads(line))

    def story(self, lines: int = 40) -> str:
        """Whether it still runs, and the end of its stderr: what a failed test shows."""
        code = self.process.poll()
        state = "running" if code is None else f"exited with code {code}"
        tail = ""
        if self.log is not None and self.log.is_file():
            tail = "\n".join(self.log.read_text(errors="replace").splitlines()[-lines:])
        return f"vahr up {state}; the end of its stderr:\n{tail or '(nothing)'}"

    def wait_event(self, command_id: str, kind: str, timeout_s: float = 20.0) -> dict[str, Any]:
        deadline = time.monotonic() + timeout_s
        while True:
            event = self.lines.get(timeout=max(0.01, deadline - time.monotonic()))
            if event.get("command_id") == command_id and event.get("event") in (kind, "failed"):
                return event


def start_up(
    state: Path,
    *extra: str,
    plaintext: bool = False,
    env: dict[str, str] | None = None,
    timeout_s: float = START_TIMEOUT_S,
) -> Up:
    """`vahr up --json --no-voice` with every port free and `extra` flags (which may give a
    port of their own, or 0 for none: the last flag wins). Never a default port: another
    `vahr up` on this machine (a developer's, another test's) may hold it. `plaintext`
    opens the plaintext development listener too (`--dev-plaintext`), on a free port; `env`
    adds to the environment (an empty model cache: `XDG_CACHE_HOME`); `timeout_s` bounds
    the start."""
    listener = ["--dev-plaintext", "--mqtt-port", str(free_port())] if plaintext else []
    process = spawn(
        [*VAHR, "up", "--json", "--no-voice", "--state-dir", str(state),
         "--api-port", str(free_port()), "--mqtts-port", str(free_port()),
         *listener, "--station-port", str(free_port()), *extra],
        started_for=state, cwd=ROOT, env={**clean_env(), **(env or {})}, stdout=subprocess.PIPE,
        stderr=(state / "up.err").open("w"),
        text=True,
    )  # fmt: skip
    first = _first_line(process, timeout_s)
    if not first:
        stop_up(process)
        raise AssertionError(f"vahr up did not start: {(state / 'up.err').read_text()}")
    up = Up(process, json.loads(first), state / "up.err")
    started.append(up)
    return up


def stop_up(process: subprocess.Popen[str]) -> None:
    if process.poll() is None:
        process.send_signal(signal.SIGTERM)
        process.wait(timeout=30)


def _first_line(process: subprocess.Popen[str], timeout_s: float) -> str:
    box: queue.Queue[str] = queue.Queue()
    assert process.stdout is not None
    stream = process.stdout
    threading.Thread(target=lambda: box.put(stream.readline()), daemon=True).start()
    try:
        return box.get(timeout=timeout_s)
    except queue.Empty:
        return ""


def say(api: str, utterance: str, *flags: str) -> dict[str, Any]:
    """`vahr say --json` against `api` (with `flags`, such as `--locale de-DE` or `--user
    ID`): the turn it prints."""
    result = subprocess.run(
        [*VAHR, "say", "--json", "--api", api, *flags, utterance],
        cwd=ROOT, env=clean_env(), capture_output=True, text=True, timeout=60,
    )  # fmt: skip
    # What `vahr say` said is the failure's message (a stack that went away, a bad flag).
    assert result.returncode == 0, f"vahr say {utterance!r}: {result.stderr.strip()}"
    turn: dict[str, Any] = json.loads(result.stdout)
    return turn
