"""The observer's console for sessions with people (`vahr experiment` without --simulate).

The observer sits beside the participant and marks what the log cannot see by itself, one
short line each (read with a timeout, so the session never blocks on the keyboard):

    u              the participant starts speaking to the assistant (both methods:
                   the keyboard-and-mouse method asks it for the weather in task II)
    q              the participant asks the assistant a question (the weather, task II
                   with keyboard and mouse): interaction time, not a command
    w              the participant looks at the robots on the screen (watching counts
                   as interaction, as in the paper)
    r              the reply has ended, or the participant is back on the puzzle
    k              the participant starts a click sequence (keyboard method)
    go THING ZONE  the order the participant clicked: navigate THING to ZONE
                   (source "console"); ends the click sequence
    send THING ACTION [ZONE] [AFTER]
                   the same with any action the procedure allows in the task; in a
                   keyboard-and-mouse session that is `navigate` only
    p [N]          N puzzle pieces solved (default 1)
    e              end the task now (the judge scores what happened)
    ?              show this help

Commands sent by the assistant between `u` and `r` are attributed to that utterance.
Orders are checked against the paper's procedure (`vahr.experiment.procedures`): a keyboard
session cannot send a compound command, and a voice session sends nothing from here.
"""

from __future__ import annotations

import itertools
import os
import select
import sys
import time
from typing import TYPE_CHECKING, Any, TextIO

from vahr.experiment.eventlog import Kind
from vahr.experiment.procedures import ProcedureViolation, check_action
from vahr.protocol import ProtocolError

if TYPE_CHECKING:
    from collections.abc import Callable

    from vahr.experiment.eventlog import EventLog
    from vahr.experiment.participant import Console

HELP = (__doc__ or "").split("\n\n", 2)[2].split("\n\nCommands")[0]
CHANNELS = {"u": "voice", "q": "voice", "k": "click", "w": "watch"}
# Marks that send no command by design: counted as interaction, not as communication (the
# log has no reply text for the judge to check a question's answer against).
NO_COMMAND = {"q", "w"}


class ObserverConsole:
    simulated = False

    def __init__(
        self,
        *,
        log: EventLog,
        console: Console,
        stdin: TextIO | None = None,
        out: Callable[[str], None] | None = None,
    ) -> None:
        self.log = log
        self.console = console
        self.stdin = stdin if stdin is not None else sys.stdin  # looked up now, not at import
        # Prompts go to stderr, so `--json` output on stdout stays one clean document.
        self.out = out or (lambda line: print(line, file=sys.stderr, flush=True))
        self._ids = itertools.count(1)
        self._open: dict[str, Any] | None = None
        self._task: str | None = None
        self._buffer = ""
        self._closed = False

    def perform(self, task: str, done: list[str] | None = None) -> None:
        self._task = task
        self.out(
            "observer: u/r mark an utterance, w/r watching, k + go THING ZONE a click "
            "sequence, p a puzzle piece, e ends the task, ? help"
        )

    def _line(self, timeout_s: float) -> str | None:
        """The next line typed, or None after `timeout_s`; "e" once input has ended.

        Reads the file descriptor directly: a buffered readline could swallow several lines
        while select() then reports nothing more to read.
        """
        if "\n" not in self._buffer and not self._closed:
            ready, _, _ = select.select([self.stdin], [], [], timeout_s)
            if ready:
                chunk = os.read(self.stdin.fileno(), 4096)
                self._buffer += chunk.decode("utf-8", "replace")
                self._closed = not chunk
        if "\n" in self._buffer:
            line, self._buffer = self._buffer.split("\n", 1)
            return line.strip()
        if self._closed:
            if self._buffer:
                line, self._buffer = self._buffer, ""
                return line.strip()
            time.sleep(timeout_s)  # input ended: nothing more will come, keep waiting politely
            return "e"
        return None

    def wait(self, decided: Callable[[], bool], timeout_s: float) -> bool:
        deadline = time.monotonic() + timeout_s
        while time.monotonic() < deadline:
            if decided():
                self._close_open()
                return True
            line = self._line(min(0.25, max(0.0, deadline - time.monotonic())))
            if line is None or not line:
                continue
            if line == "e":
                self._close_open()
                return decided()
            try:
                self.handle(line)
            except (ValueError, ProtocolError) as err:
                self.out(f"observer: {err}")
        self._close_open()
        return decided()

    def handle(self, line: str) -> None:
        word, *args = line.split()
        if word == "?":
            self.out(HELP)
        elif word == "p":
            count = int(args[0]) if args else 1
            self.log.append(
                Kind.OBSERVER, {"what": "puzzle_piece", "count": count}, task=self._task
            )
        elif word in CHANNELS:
            self._close_open()
            channel = CHANNELS[word]
            body: dict[str, Any] = {"id": f"{self._task}-{next(self._ids)}", "channel": channel}
            if word in NO_COMMAND:
                body["counts"] = False
            entry = self.log.append(Kind.INTERACTION_STARTED, body, task=self._task)
            self._open = {
                "id": entry.data["id"],
                "channel": channel,
                "seq": entry.seq,
                "counts": word not in NO_COMMAND,
            }
        elif word == "r":
            self._close_open()
        elif word in ("go", "send"):
            if word == "go" and len(args) != 2:
                raise ValueError("go THING ZONE")
            if word == "send" and len(args) < 2:
                raise ValueError("send THING ACTION [ZONE] [AFTER]")
            thing, action, rest = (
                (args[0], "navigate", args[1:]) if word == "go" else (args[0], args[1], args[2:])
            )
            self._send(thing, action, rest)
        else:
            raise ValueError(f"{word!r} is not an observer command; ? shows them")

    def _send(self, thing: str, action: str, rest: list[str]) -> None:
        if self.console.method != "keyboard":
            raise ProcedureViolation(
                f"the {self.console.method} method gives its orders by voice; "
                "go and send are for keyboard-and-mouse sessions"
            )
        check_action(self.console.method, self._task, action)  # before opening a sequence
        params: dict[str, Any] = {}
        if rest:
            params["zone"] = rest[0].upper()
        if action == "sequential_delivery":
            params["after"] = rest[1] if len(rest) > 1 else None
        if self._open is None or self._open["channel"] != "click":
            self.handle("k")
        command_id = self.console.send(thing, action, params, task=self._task)
        self._close_open(commands=[command_id])

    def _close_open(self, commands: list[str] | None = None) -> None:
        if self._open is None:
            return
        opened, self._open = self._open, None
        if commands is None:
            commands = [
                str(e.data.get("id"))
                for e in self.log.entries(Kind.COMMAND)
                if e.seq > opened["seq"] and e.data.get("source") == "alexa"
            ]
        body: dict[str, Any] = {"id": opened["id"], "channel": opened["channel"]}
        body["commands"] = commands if opened["counts"] else []
        if not opened["counts"]:
            body["counts"] = False
        self.log.append(Kind.INTERACTION_ENDED, body, task=self._task)
