"""The room channel on a real mosquitto: a robot's `RoomVoice` asks, the local assistant
recognizes the question from audio, answers through `ask`, and the robot understands the
spoken answer. `ask` here is the weather intent's contract (the skill's own answers); the
end-to-end test with the skill and a robot agent is test_voice_weather_task.py.

Both ends speak over the `Link` port; here the robot's link is the lab's paho client (the
agent's own awscrt link carries it in test_voice_weather_task.py)."""

from __future__ import annotations

import asyncio
import threading
from typing import TYPE_CHECKING

import pytest

from robot_agent.config import AgentConfig, VoiceSettings
from robot_agent.voice.factories import room
from vahr.local.room_assistant import Exchange, offline_room_assistant
from vahr.plumbing.mqtt import MqttClient, MqttEndpoint
from vahr.protocol import topics
from vahr.speech.room_channel import Utterance
from vahr.speech.tts import EspeakSynthesizer

if TYPE_CHECKING:
    from collections.abc import Iterator

    from robot_agent.voice.room import RoomVoice
    from vahr.twin.broker import Mosquitto

QUESTION = "Alexa, ask robot fleet what the weather is"
WEATHER_ANSWERS = {"sunny": "The weather is sunny.", "rainy": "The weather is rainy."}


class Skill:
    """Answers the weather question the way the skill does, for a settable weather."""

    def __init__(self) -> None:
        self.weather = "sunny"
        self.requests: list[str] = []

    def ask(self, utterance: str) -> str:
        self.requests.append(utterance)
        return WEATHER_ANSWERS[self.weather]


class RobotInTheRoom:
    """A robot's room voice on its own connection to the broker."""

    def __init__(self, url: str, thing: str, synthesizer: str = "en-us+f2") -> None:
        self.link = MqttClient(MqttEndpoint(port=int(url.rsplit(":", 1)[1]))).connect()
        config = AgentConfig(thing=thing, voice=VoiceSettings(synthesizer=synthesizer))
        self.voice: RoomVoice = room(thing=thing, config=config, link=self.link)

    def close(self) -> None:
        self.link.stop()


@pytest.fixture
def room_setup(mosquitto: Mosquitto) -> Iterator[tuple[Skill, list[Exchange], str]]:
    skill = Skill()
    exchanges: list[Exchange] = []
    url = f"mqtt://127.0.0.1:{mosquitto.config.plain_port}"
    client = MqttClient(MqttEndpoint(port=int(mosquitto.config.plain_port or 0))).connect()
    assistant = offline_room_assistant(client, skill.ask)
    assistant.on_exchange = exchanges.append
    assistant.start()
    try:
        yield skill, exchanges, url
    finally:
        assistant.stop()
        client.stop()


@pytest.mark.parametrize("weather", ["sunny", "rainy"])
def test_the_robot_asks_and_understands_the_spoken_answer(
    room_setup: tuple[Skill, list[Exchange], str], weather: str
) -> None:
    skill, exchanges, url = room_setup
    skill.weather = weather
    # Given a robot's room voice on the broker
    robot = RobotInTheRoom(url, "placebot1", synthesizer="en-us+m3")
    voice = robot.voice
    try:
        # When it asks the weather question aloud and listens
        async def converse() -> tuple[str, str, float]:
            await voice.say(QUESTION)
            heard = await voice.listen(10.0)
            return heard.text, heard.intent, heard.confidence

        text, intent, confidence = asyncio.run(converse())
    finally:
        robot.close()
    # Then the assistant recognized the question from audio and asked the skill
    assert skill.requests == ["ask robot fleet what the weather is"]
    assert exchanges[0].heard == "alexa ask robot fleet what the weather is"
    # And the robot understood the answer it heard
    assert (text, intent) == (f"the weather is {weather}", weather)
    assert 0.0 < confidence <= 1.0


def test_speech_not_for_the_assistant_gets_no_answer(
    room_setup: tuple[Skill, list[Exchange], str],
) -> None:
    skill, exchanges, url = room_setup
    robot = RobotInTheRoom(url, "placebot2")
    voice = robot.voice
    try:

        async def acknowledge() -> tuple[str, str]:
            await voice.say("Thank you. It is sunny, so I am delivering to zone A.")
            heard = await voice.listen(2.0)
            return heard.text, heard.intent

        assert asyncio.run(acknowledge()) == ("", "unknown")
    finally:
        robot.close()
    assert skill.requests == []
    assert [(e.thing, e.heard, e.answer) for e in exchanges] == [("placebot2", "", None)]


def test_an_answer_to_an_older_question_is_ignored(
    room_setup: tuple[Skill, list[Exchange], str],
) -> None:
    _, _, url = room_setup
    port = int(url.rsplit(":", 1)[1])
    robot = RobotInTheRoom(url, "placebot1")
    voice = robot.voice
    stale_sent = threading.Event()
    try:

        async def converse() -> tuple[str, str]:
            await voice.say("Hello there.")  # not a question: the assistant stays silent
            # A late answer to some earlier question arrives meanwhile.
            stale = Utterance.new(
                "placebot1",
                "assistant",
                EspeakSynthesizer().synthesize("The weather is rainy."),
                in_reply_to="an-earlier-question",
            )
            with MqttClient(MqttEndpoint(port=port)) as other:
                other.publish(topics.room_assistant_speech("placebot1"), stale.encode())
            stale_sent.set()
            heard = await voice.listen(1.5)
            return heard.text, heard.intent

        assert asyncio.run(converse()) == ("", "unknown")
    finally:
        robot.close()
    assert stale_sent.is_set()


def test_a_broken_room_message_is_ignored_and_the_room_keeps_answering(
    room_setup: tuple[Skill, list[Exchange], str],
) -> None:
    skill, _, url = room_setup
    port = int(url.rsplit(":", 1)[1])
    with MqttClient(MqttEndpoint(port=port)) as intruder:
        intruder.publish(topics.room_robot_speech("placebot1"), b"not json")
        intruder.publish(topics.room_robot_speech("placebot1"), b'{"id": "x"}')
    robot = RobotInTheRoom(url, "placebot1")
    voice = robot.voice
    try:

        async def converse() -> str:
            await voice.say(QUESTION)
            return (await voice.listen(10.0)).intent

        assert asyncio.run(converse()) == "sunny"
    finally:
        robot.close()
