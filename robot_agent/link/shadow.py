"""The classic device shadow of one robot, spoken over a `Link` ($aws/things/{thing}/shadow/...).

The robot reports its full state on every connection and then only when it changes.
A rejected update (409 version conflict) is answered by re-reading the shadow and sending
the latest state again. A command written as desired state,
`{"state": {"desired": {"command": {<command message>}}}}`, is handed to the agent like a
command from the command topic, after which desired state is cleared with
`{"state": {"desired": null}}`.
"""

from __future__ import annotations

import json
import logging
from typing import TYPE_CHECKING, Any

import msgspec

from vahr.protocol import topics

if TYPE_CHECKING:
    from collections.abc import Callable

    from vahr.protocol import Reported
    from vahr.protocol.link import Link

log = logging.getLogger(__name__)

# Conflicts are retried through a fresh `get`; this bounds a livelock with another writer.
MAX_CONFLICT_RETRIES = 5


class ShadowSync:
    """Keeps the shadow's reported state equal to the robot's and applies desired commands."""

    def __init__(
        self, *, thing: str, link: Link, on_desired_command: Callable[[bytes], None]
    ) -> None:
        self.thing = thing
        self._link = link
        self._on_desired_command = on_desired_command
        self._latest: Reported | None = None
        self._token = 0
        self._conflicts = 0
        self._resend_after_get = False
        self.updates_sent = 0
        self.rejections = 0
        # Not `update/accepted`: nothing in it is news to the robot, and on AWS every
        # delivery is a billed message (two with its PUBACK) for each update it sends.
        for operation, handler in (
            ("update/rejected", self._on_update_rejected),
            ("update/delta", self._on_delta),
            ("get/accepted", self._on_get_accepted),
            ("get/rejected", self._on_get_rejected),
        ):
            link.add_route(topics.shadow(thing, operation), handler)

    def report(self, state: Reported) -> None:
        """Publish the full reported state (the caller publishes only on change)."""
        # A new state starts a new allowance of conflict retries.
        self._conflicts = 0
        self._send(state)

    def _send(self, state: Reported) -> None:
        self._latest = state
        self._token += 1
        self.updates_sent += 1
        self._link.publish(
            topics.shadow(self.thing, "update"),
            state.to_payload(client_token=f"{self.thing}-{self._token}"),
        )

    def request_document(self) -> None:
        """Ask for the whole shadow (answered on get/accepted, where desired state is read)."""
        self._link.publish(topics.shadow(self.thing, "get"), b"{}")

    def clear_desired(self) -> None:
        self._link.publish(topics.shadow(self.thing, "update"), b'{"state":{"desired":null}}')

    # -- responses ----------------------------------------------------------------------

    def _on_update_rejected(self, topic: str, payload: bytes) -> None:
        self.rejections += 1
        error = _json_object(payload)
        code, message = error.get("code"), error.get("message", "")
        if code == 409 and self._conflicts < MAX_CONFLICT_RETRIES:
            self._conflicts += 1
            log.info("shadow update conflicted (%s); re-reading and retrying", message)
            self._resend_after_get = True
            self.request_document()
            return
        log.warning("shadow update rejected: %s %s", code, message)

    def _on_get_rejected(self, topic: str, payload: bytes) -> None:
        error = _json_object(payload)
        if error.get("code") == 404:
            # No shadow yet: the first update creates it.
            if self._latest is not None and self._resend_after_get:
                self._resend_after_get = False
                self._send(self._latest)
            return
        log.warning("shadow get rejected: %s %s", error.get("code"), error.get("message"))

    def _on_get_accepted(self, topic: str, payload: bytes) -> None:
        document = _json_object(payload)
        if self._resend_after_get and self._latest is not None:
            self._resend_after_get = False
            self._send(self._latest)
        state = document.get("state")
        desired = state.get("desired") if isinstance(state, dict) else None
        if isinstance(desired, dict):
            self._apply_desired(desired)

    def _on_delta(self, topic: str, payload: bytes) -> None:
        delta = _json_object(payload).get("state")
        if isinstance(delta, dict):
            self._apply_desired(delta)

    def _apply_desired(self, desired: dict[str, Any]) -> None:
        command = desired.get("command")
        if command is None:
            return
        # The command travels the same path as one from the command topic (decoding,
        # rejection with a reason, de-duplication), so desired state has no special rules.
        try:
            payload = msgspec.json.encode(command)
        except RecursionError:  # only a document no shadow service would accept
            log.warning("%s: ignoring a desired command nested too deeply to read", self.thing)
        else:
            self._on_desired_command(payload)
        self.clear_desired()


def _json_object(payload: bytes) -> dict[str, Any]:
    try:
        value = json.loads(payload)
    except (ValueError, RecursionError):  # nested deeper than the parser goes
        return {}
    return value if isinstance(value, dict) else {}
