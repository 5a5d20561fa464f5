"""What a reading does: the robot commands the real skill sends for an understanding.

A reading other than the label ("wrong" in `vahr.assistant.evaluation.outcome`) is not
always a robot sent where nobody asked: the skill may ask which robot is meant, refuse, or
send what the label means in other words. The issue's targets count wrong *actions*, so the
benches count them here by effect too. The understanding is handed to the Alexa simulator
(as push-to-talk hands in what it heard), which sends the real skill (ask-sdk-core, under
moto) one request in a fresh session. The fleet is the default one: idle, connected robots
at the loading zone, and a sunny experiment. The commands the skill publishes on the
robots' topics are the effect; the label's own effect is found the same way.
"""

from __future__ import annotations

import json
import os
import sys
from pathlib import Path
from typing import TYPE_CHECKING, Any
from unittest import mock

# The skill's package, for benchmarks (pytest puts it on the path itself).
sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "lambda"))

from vahr.assistant.evaluation import LabelledUtterance, labelled_understanding  # noqa: E402
from vahr.assistant.simulator import AlexaSimulator  # noqa: E402
from vahr.domain import load_fleet
from vahr.domain.invocation import FALLBACK_INTENT
from vahr.protocol import MOTION_ACTIONS, ExperimentState, Reported, topics

if TYPE_CHECKING:
    from types import TracebackType

    from vahr.assistant.nlu import InteractionModel, Understanding

REGION = "us-east-1"
# The skill waits this long for robots to acknowledge; nobody answers here, and what it
# published is all that is counted.
ACK_TIMEOUT_S = 0.01
VERDICTS = ("as labelled", "moved wrongly", "stopped wrongly", "less or nothing sent")

# An effect: the commands sent, each (topic, action, params as JSON), in order.
Effect = tuple[tuple[str, str, str], ...]


class SkillEffects:
    """The effects of understandings on the real skill, each found once; a context manager
    (the skill runs under moto while it is open)."""

    def __init__(self, model: InteractionModel) -> None:
        self.model = model
        self.fleet = load_fleet()
        self._found: dict[str, Effect] = {}
        self._moto: Any = None
        self._environment: Any = None

    def __enter__(self) -> SkillEffects:
        import boto3
        from moto import mock_aws
        from moto.core import DEFAULT_ACCOUNT_ID
        from moto.iotdata.models import iotdata_backends

        from skill.app import make_lambda_handler
        from skill.config import SkillConfig
        from tests.support.shared_models import default_session

        # moto's credentials and region, no endpoint or fleet file of a real run; the
        # environment is given back as it was on exit.
        kept = ("AWS_ENDPOINT_URL", "AWS_ENDPOINT_URL_IOT_DATA_PLANE", "VAHR_FLEET_FILE")
        environment = {k: v for k, v in os.environ.items() if k not in kept}
        environment.setdefault("AWS_ACCESS_KEY_ID", "testing")
        environment.setdefault("AWS_SECRET_ACCESS_KEY", "testing")
        self._environment = mock.patch.dict(
            os.environ, {**environment, "AWS_DEFAULT_REGION": REGION}, clear=True
        )
        self._environment.start()
        self._moto = mock_aws()
        self._moto.start()
        default_session()
        iot, self._data = boto3.client("iot"), boto3.client("iot-data")
        for thing in (*self.fleet.robot_things, self.fleet.experiment_thing):
            iot.create_thing(thingName=thing)
        sunny = ExperimentState(weather="sunny").to_payload()
        self._data.update_thing_shadow(thingName=self.fleet.experiment_thing, payload=sunny)
        self._published = iotdata_backends[DEFAULT_ACCOUNT_ID][REGION].published_payloads
        self._handler = make_lambda_handler(
            SkillConfig(ack_timeout_s=ACK_TIMEOUT_S, log_level="WARNING")
        )
        return self

    def __exit__(
        self,
        kind: type[BaseException] | None,
        error: BaseException | None,
        trace: TracebackType | None,
    ) -> None:
        self._moto.stop()
        self._environment.stop()

    def of(self, understanding: Understanding) -> Effect:
        """The commands the skill sends when `understanding` is what was heard."""
        if understanding.intent == FALLBACK_INTENT:
            return ()  # the station says "Sorry" and sends the skill nothing
        key = repr((understanding.intent, sorted(understanding.slots.items())))
        key += repr(understanding.needs_confirmation)
        if key not in self._found:
            self._found[key] = self._run(understanding)
        return self._found[key]

    def verdict(self, item: LabelledUtterance, heard: Understanding) -> str:
        """One of VERDICTS: `as labelled` (the label's commands, or none where it has
        none); `moved wrongly` (a motion command the label does not send: a robot sent
        where nobody asked, the worst error); `stopped wrongly` (another command the label
        does not send, a stop: the safe side of a mishearing, still not what was said);
        `less or nothing sent` (some or none of the label's commands: the skill asked
        which robot or zone, asked to confirm, refused, or the words were not caught)."""
        done = self.of(heard)
        meant = (
            ()
            if item.intent == FALLBACK_INTENT
            else self.of(labelled_understanding(self.model, item))
        )
        if set(done) == set(meant):
            return "as labelled"
        extra = set(done) - set(meant)
        if any(action in MOTION_ACTIONS for _, action, _ in extra):
            return "moved wrongly"
        return "stopped wrongly" if extra else "less or nothing sent"

    def _run(self, understanding: Understanding) -> Effect:
        for thing in self.fleet.robot_things:
            idle = Reported(status="idle", zone="LOADING", connected=True)
            self._data.update_thing_shadow(thingName=thing, payload=idle.to_payload())
        self._published.clear()
        AlexaSimulator(self.model, self._handler).say("heard", understanding=understanding)
        commands = (_command(topic, payload) for topic, payload in self._published)
        return tuple(command for command in commands if command is not None)


def _command(topic: str, payload: bytes) -> tuple[str, str, str] | None:
    parsed = topics.parse_robot_topic(topic)
    if topic != topics.FLEET_CMD and (parsed is None or parsed[1] != "cmd"):
        return None
    body = json.loads(payload)
    return topic, body["action"], json.dumps(body.get("params", {}), sort_keys=True)
