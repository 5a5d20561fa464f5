"""Where the station's typed and spoken requests go: the Alexa simulator and the real skill.

- `SimulatorAssistant` calls an `AlexaSimulator` in-process: `vahr up`'s own (whose turns
  the local stack publishes for every station to see), or one the station builds around
  the skill for a deployment it reaches only through AWS's iot-data endpoint
  (`vahr station` against AWS IoT Core; its turns go to the station's own feed).
- `HttpAssistant` posts to a running local stack's `POST /vahr/say` (`vahr station --api`
  pointed at `vahr up`), as `vahr say` does.

Both return the turn as `vahr say --json` prints it.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any, Protocol

from vahr.errors import VahrError

if TYPE_CHECKING:
    from vahr.local.alexa.simulator import AlexaSimulator

Turn = dict[str, Any]


class Assistant(Protocol):
    def ask(self, utterance: str, *, origin: str, heard: dict[str, Any] | None = None) -> Turn:
        """Say `utterance` to the assistant; `origin` names who spoke, `heard` what the
        recognizer made of it. Raises VahrError when the assistant cannot be reached."""
        ...


class SimulatorAssistant:
    """The Alexa simulator in this process."""

    def __init__(self, simulator: AlexaSimulator) -> None:
        self.simulator = simulator

    def ask(self, utterance: str, *, origin: str, heard: dict[str, Any] | None = None) -> Turn:
        turn = self.simulator.say(utterance, origin=origin, heard=heard)
        return {**turn.to_json(), "utterance": utterance}


class HttpAssistant:
    """A running local stack's `POST /vahr/say`."""

    def __init__(self, api_url: str) -> None:
        self.api_url = api_url

    def ask(self, utterance: str, *, origin: str, heard: dict[str, Any] | None = None) -> Turn:
        from vahr.local.client import call

        body: dict[str, Any] = {"utterance": utterance, "origin": origin}
        if heard is not None:
            body["heard"] = heard
        turn = call(self.api_url, "POST", "/vahr/say", body)
        if not isinstance(turn, dict) or "speech" not in turn:
            raise VahrError(f"{self.api_url}/vahr/say did not answer with a turn")
        return {**turn, "utterance": utterance}
