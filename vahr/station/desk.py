"""The station's side of a running experiment session.

The session runs in `vahr experiment` (maybe on another machine); the station learns of it
from the retained status on `topics.EXPERIMENT_STATUS` (kept by the `Feed`; published by
`vahr.experiment.station_link`) and sends what the participant did on the page to
`topics.EXPERIMENT_INPUT`, where the session's recorder logs it
(`vahr.experiment.recorder.Recorder`). While a session runs, orders from the panel follow
the paper's procedure for its method and task (`vahr.experiment.procedures`).
"""

from __future__ import annotations

from datetime import UTC, datetime
from typing import TYPE_CHECKING, Any

import msgspec

from vahr.experiment.procedures import ProcedureViolation, check_action
from vahr.protocol import ProtocolError, topics
from vahr.protocol.errors import from_validation_error
from vahr.protocol.station_topics import Interaction, PuzzleInput

if TYPE_CHECKING:
    from collections.abc import Callable

    from vahr.station.feed import Feed

# Orders that are always allowed: stopping a robot is a safety control, never withheld. In
# a session the judge still sees it as an order outside the paper's procedure.
SAFETY_ACTIONS = frozenset({"stop"})


class NoSession(Exception):
    """No experiment session is running: the participant's input has nowhere to go."""


class Desk:
    """Check orders against the running session's procedure; forward the participant's input."""

    def __init__(self, feed: Feed, publish: Callable[[str, bytes], None]) -> None:
        self.feed = feed
        self._publish = publish

    def session(self) -> dict[str, Any] | None:
        """The running session's status, or None (no session, or it has ended)."""
        status = self.feed.experiment
        if status is None or status.get("ended"):
            return None
        return status

    def check_order(self, action: str) -> None:
        """Raise ProcedureViolation if the running session's procedure forbids `action`."""
        status = self.session()
        if status is None or action in SAFETY_ACTIONS:
            return
        if status.get("method") != "keyboard":
            raise ProcedureViolation(
                f"session {status['session']} uses the {status.get('method')} method: "
                "its orders are given by voice, not with the panel"
            )
        check_action("keyboard", status.get("task"), action)

    def forward(self, kind: str, body: dict[str, Any]) -> bool:
        """Send the participant's `interaction` or `puzzle` input to the session's log.

        Returns False when no session is running (the input is not logged anywhere);
        raises ProtocolError when the input is malformed.
        """
        if kind not in ("interaction", "puzzle"):
            raise ProtocolError("kind", f"{kind!r} is not interaction or puzzle")
        status = self.session()
        if status is None:
            return False
        # The session is the one running, whatever the page says.
        fields = {**body, "session": status["session"], "kind": kind}
        fields.setdefault("sent", datetime.now(UTC).isoformat())
        shape: type[Interaction] | type[PuzzleInput] = (
            Interaction if kind == "interaction" else PuzzleInput
        )
        try:
            message = msgspec.convert(fields, shape, strict=False)
        except msgspec.ValidationError as err:
            raise from_validation_error(err) from err
        self._publish(topics.EXPERIMENT_INPUT, msgspec.json.encode(message))
        return True
