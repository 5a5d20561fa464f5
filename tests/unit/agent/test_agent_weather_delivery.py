"""weather_delivery: the conversation the executor holds through the Voice port.

The voice here is a scripted stand-in for the assistant on the other side of the room
(the real audio path belongs to the voice adapters and has its own tests): it records what
the robot said and answers with what a person would hear from the assistant.
"""

from __future__ import annotations

import asyncio
from typing import TYPE_CHECKING, Any

import pytest

from robot_agent.config import ExecutorSettings
from robot_agent.voice.port import Heard
from tests.unit.agent.conftest import make_executor
from vahr.domain.invocation import WEATHER_QUESTION
from vahr.protocol import new_command
from vahr.speech.errors import SpeechError

if TYPE_CHECKING:
    from vahr.domain import Fleet


class ScriptedAssistant:
    """Answers each question with the next scripted `Heard` (or raises a SpeechError)."""

    def __init__(self, *answers: Heard | SpeechError) -> None:
        self.answers = list(answers)
        self.said: list[str] = []
        self.listens: list[float] = []
        self.closed = False
        self.config: object = None

    async def say(self, text: str) -> None:
        self.said.append(text)

    def close(self) -> None:
        self.closed = True

    async def listen(self, timeout_s: float) -> Heard:
        self.listens.append(timeout_s)
        answer = self.answers.pop(0)
        if isinstance(answer, SpeechError):
            raise answer
        return answer


SUNNY = Heard("The weather is sunny.", "sunny", 0.93)
RAINY = Heard("The weather is rainy. Take an umbrella.", "rainy", 0.88)
MUMBLE = Heard("the whether is funny", "unknown", 0.21)


def weather() -> object:
    return new_command("weather_delivery", None, source="alexa", command_id="w1")


async def test_sunny_means_a_delivery_to_a(fleet: Fleet) -> None:
    assistant = ScriptedAssistant(SUNNY)
    executor, rec, _ = make_executor(fleet, voice=assistant)
    executor.execute(weather())  # type: ignore[arg-type]
    await executor.wait_idle()
    assert assistant.said == [
        WEATHER_QUESTION,
        "Thank you. It is sunny, so I am delivering to zone A.",
    ]
    said = [e.text for e in rec.events if e.event == "said"]
    assert said == assistant.said
    assert rec.first("heard").text == "The weather is sunny."
    interpreted = rec.first("interpreted")
    assert (interpreted.intent, interpreted.confidence) == ("sunny", 0.93)
    assert rec.first("delivered").zone == "A"
    assert rec.states[-1].last_command is not None and rec.states[-1].last_command.result == "done"


async def test_rainy_means_a_delivery_to_c(fleet: Fleet) -> None:
    executor, rec, _ = make_executor(fleet, voice=ScriptedAssistant(RAINY))
    executor.execute(weather())  # type: ignore[arg-type]
    await executor.wait_idle()
    assert rec.first("delivered").zone == "C"


async def test_one_unknown_answer_is_asked_again(fleet: Fleet) -> None:
    assistant = ScriptedAssistant(MUMBLE, RAINY)
    executor, rec, _ = make_executor(fleet, voice=assistant)
    executor.execute(weather())  # type: ignore[arg-type]
    await executor.wait_idle()
    assert assistant.said[:2] == [WEATHER_QUESTION, WEATHER_QUESTION]
    assert [e.intent for e in rec.events if e.event == "interpreted"] == ["unknown", "rainy"]
    assert rec.first("delivered").zone == "C"


async def test_two_unknown_answers_fail_with_a_reason_and_nothing_moves(fleet: Fleet) -> None:
    executor, rec, backend = make_executor(fleet, voice=ScriptedAssistant(MUMBLE, MUMBLE))
    start = backend.pose
    executor.execute(weather())  # type: ignore[arg-type]
    await executor.wait_idle()
    reason = "did not understand the weather answer twice (last heard: 'the whether is funny')"
    assert rec.first("failed").reason == reason
    assert rec.states[-1].last_command is not None and rec.states[-1].last_command.reason == reason
    assert backend.pose == start


async def test_without_a_voice_it_fails_with_voice_not_configured(fleet: Fleet) -> None:
    executor, rec, _ = make_executor(fleet, voice=None)
    executor.execute(weather())  # type: ignore[arg-type]
    await executor.wait_idle()
    assert rec.first("failed").reason == "voice not configured"
    assert "said" not in rec.kinds()
    final = rec.states[-1]
    assert final.last_command is not None
    assert (final.last_command.result, final.last_command.reason) == (
        "failed",
        "voice not configured",
    )


async def test_a_broken_voice_path_fails_with_its_reason(fleet: Fleet) -> None:
    executor, rec, _ = make_executor(fleet, voice=ScriptedAssistant(SpeechError("no audio device")))
    executor.execute(weather())  # type: ignore[arg-type]
    await executor.wait_idle()
    assert rec.first("failed").reason == "voice failed: no audio device"


# The agent's link, which these factories never use.
NO_LINK: Any = object()


def scripted_rainy_assistant(thing: str) -> ScriptedAssistant:
    """A `--voice` factory for tests of the CLI path: the assistant says it is rainy."""
    return ScriptedAssistant(Heard(f"The weather is rainy, {thing}.", "rainy", 0.9))


def test_the_voice_factory_named_in_the_config_is_built_with_the_thing() -> None:
    from robot_agent.assembly import build_voice
    from robot_agent.config import AgentConfig, VoiceSettings

    config = AgentConfig(
        thing="placebot1",
        voice=VoiceSettings(
            factory="tests.unit.agent.test_agent_weather_delivery:scripted_rainy_assistant"
        ),
    )
    voice = build_voice(config, NO_LINK)
    # pytest imports this file under another module name, so compare by behaviour.
    assert voice is not None and type(voice).__name__ == "ScriptedAssistant"
    assert voice.answers[0].text == "The weather is rainy, placebot1."  # type: ignore[attr-defined]
    assert build_voice(AgentConfig(thing="placebot1"), NO_LINK) is None


def scripted_with_config(thing: str, config: object, link: object) -> ScriptedAssistant:
    """A factory that, like the room voice, takes the agent's configuration and link."""
    assistant = ScriptedAssistant(SUNNY)
    assistant.config = config
    assistant.link = link
    return assistant


def failing_voice(thing: str) -> ScriptedAssistant:
    raise SpeechError("no sound card")


def test_a_factory_that_takes_the_config_gets_it_and_a_failing_one_is_one_line() -> None:
    from robot_agent.assembly import build_voice
    from robot_agent.config import AgentConfig, VoiceSettings
    from vahr.errors import VahrError

    module = "tests.unit.agent.test_agent_weather_delivery"
    config = AgentConfig(
        thing="placebot1", voice=VoiceSettings(factory=f"{module}:scripted_with_config")
    )
    voice = build_voice(config, NO_LINK)
    assert voice is not None and voice.config is config  # type: ignore[attr-defined]
    assert voice.link is NO_LINK  # type: ignore[attr-defined]
    failing = AgentConfig(thing="placebot1", voice=VoiceSettings(factory=f"{module}:failing_voice"))
    with pytest.raises(VahrError, match="no sound card"):
        build_voice(failing, NO_LINK)


async def test_the_voice_is_closed_when_the_executor_closes(fleet: Fleet) -> None:
    assistant = ScriptedAssistant()
    executor, _, _ = make_executor(fleet, voice=assistant)
    await executor.close()
    assert assistant.closed


class SilentDevice(ScriptedAssistant):
    """A voice whose audio device hangs: speaking never returns."""

    async def say(self, text: str) -> None:
        await asyncio.Event().wait()


async def test_a_hung_voice_fails_the_task_instead_of_stalling_it(fleet: Fleet) -> None:
    # Given a robot whose speaker hangs, with a short bound on speaking
    settings = ExecutorSettings(stuck_after_s=120, speak_timeout_s=0.2)
    executor, rec, _ = make_executor(fleet, voice=SilentDevice(SUNNY), settings=settings)
    # When it is asked to deliver based on the weather
    executor.execute(weather())  # type: ignore[arg-type]
    await asyncio.wait_for(executor.wait_idle(), 10)
    # Then the task fails with the reason, and nothing is delivered
    assert rec.first("failed").reason == "voice failed: speaking took longer than 0.2 s"
    assert not [e for e in rec.events if e.event == "delivered"]
