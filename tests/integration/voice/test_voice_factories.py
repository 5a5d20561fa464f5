"""The factories `robot-agent run --voice MODULE:FACTORY` builds a voice with, from the
agent's configuration (environment variables mapped onto it by `load_config`)."""

from __future__ import annotations

import argparse
import shutil
from typing import TYPE_CHECKING

import pytest

from robot_agent.config import AgentConfig, load_config
from robot_agent.voice.devices import DeviceVoice
from robot_agent.voice.factories import device, room
from robot_agent.voice.lex import LexInterpreter
from robot_agent.voice.room import RoomVoice
from vahr.errors import VahrError
from vahr.speech.errors import SpeechError

if TYPE_CHECKING:
    from pathlib import Path

    from vahr.twin.broker import Mosquitto


def config_from_environment(environ: dict[str, str], **flags: object) -> AgentConfig:
    return load_config(argparse.Namespace(**flags), environ)


def test_the_room_voice_speaks_over_the_link_it_is_given(mosquitto: Mosquitto) -> None:
    from vahr.plumbing.mqtt import MqttClient, MqttEndpoint
    from vahr.protocol import topics

    # Given a link to the broker (the agent's own, when robot-agent run builds the voice)
    link = MqttClient(MqttEndpoint(port=int(mosquitto.config.plain_port or 0))).connect()
    try:
        # When the factory builds the voice
        voice = room(thing="placebot1", config=AgentConfig(thing="placebot1"), link=link)
        # Then it is the robot's room voice, already listening for the assistant on that link
        assert isinstance(voice, RoomVoice)
        assert voice.thing == "placebot1"
        assert [f for f, _, _ in link._handlers] == [topics.room_assistant_speech("placebot1")]
    finally:
        link.stop()


def test_the_device_voice_takes_its_commands_from_the_environment() -> None:
    config = config_from_environment(
        {"VAHR_PLAY_COMMAND": "sox -t wav - -d", "VAHR_RECORD_COMMAND": "sox -d -t raw -"}
    )
    voice = device(thing="placebot1", config=config)
    assert isinstance(voice, DeviceVoice)
    assert voice.player == ["sox", "-t", "wav", "-", "-d"]
    assert voice.recorder == ["sox", "-d", "-t", "raw", "-"]


@pytest.mark.skipif(shutil.which("aplay") is not None, reason="alsa-utils is installed here")
def test_the_device_voice_without_alsa_utils_says_what_to_install() -> None:
    with pytest.raises(SpeechError, match="install alsa-utils"):
        device(thing="placebot1", config=config_from_environment({}))


def test_lex_needs_its_settings(tmp_path: Path) -> None:
    env = {"VAHR_PLAY_COMMAND": "true", "VAHR_RECORD_COMMAND": "true", "VAHR_INTERPRETER": "lex"}
    with pytest.raises(SpeechError, match="certificate and key"):
        device(thing="placebot1", config=config_from_environment(env))
    cert, key = tmp_path / "c.pem", tmp_path / "k.pem"
    env |= {"VAHR_ROBOT_CERT": str(cert), "VAHR_ROBOT_KEY": str(key)}
    with pytest.raises(SpeechError, match="VAHR_IOT_CREDENTIALS_ENDPOINT"):
        device(thing="placebot1", config=config_from_environment(env))
    with pytest.raises(VahrError, match="voice.interpreter"):
        config_from_environment(env | {"VAHR_INTERPRETER": "oracle"})


def test_lex_is_chosen_with_the_robot_certificate(tmp_path: Path) -> None:
    from vahr.pki import LocalCA

    robot = LocalCA.load_or_create(tmp_path / "state").issue_client("placebot1", tmp_path / "r")
    env = {
        "VAHR_PLAY_COMMAND": "true", "VAHR_RECORD_COMMAND": "true", "VAHR_INTERPRETER": "lex",
        "VAHR_IOT_CREDENTIALS_ENDPOINT": "c1abc.credentials.iot.eu-west-1.amazonaws.com",
        "VAHR_LEX_BOT_ID": "BOTID12345", "VAHR_LEX_BOT_ALIAS_ID": "ALIAS12345",
        "VAHR_LEX_REGION": "eu-west-1",
    }  # fmt: skip
    config = config_from_environment(
        env, thing="placebot1", endpoint="x.iot.eu-west-1.amazonaws.com",
        cert=str(robot.cert_file), key=str(robot.key_file), ca=str(robot.ca_file),
    )  # fmt: skip
    voice = device(thing="placebot1", config=config)
    lex = voice.hearing.interpreter
    assert isinstance(lex, LexInterpreter)
    assert (lex.bot_id, lex.bot_alias_id, lex.locale_id, lex.session_id, lex.region) == (
        "BOTID12345", "ALIAS12345", "en_US", "placebot1", "eu-west-1",
    )  # fmt: skip
