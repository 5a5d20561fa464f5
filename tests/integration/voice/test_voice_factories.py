"""The factories `robot-agent run --voice MODULE:FACTORY` builds a voice with."""

from __future__ import annotations

import shutil
from typing import TYPE_CHECKING

import pytest

from robot_agent.config import AgentConfig
from robot_agent.voice.devices import DeviceVoice
from robot_agent.voice.factories import device, room
from robot_agent.voice.lex import LexInterpreter
from robot_agent.voice.port import VoiceError
from robot_agent.voice.room import RoomVoice

if TYPE_CHECKING:
    from pathlib import Path

    from vahr.local.broker import Mosquitto


def test_the_room_voice_uses_the_agents_broker(mosquitto: Mosquitto) -> None:
    # Given the agent's configuration with a plaintext development broker, and no variables
    config = AgentConfig(thing="placebot1", broker=mosquitto.plain_url)
    # When the factory builds the voice
    voice = room(thing="placebot1", config=config, environ={})
    try:
        assert isinstance(voice, RoomVoice)
        assert voice.thing == "placebot1"
    finally:
        voice.close()


def test_the_room_voice_on_a_broker_that_is_down_is_one_clear_error() -> None:
    from vahr.errors import VahrError
    from vahr.local.ports import free_port

    with pytest.raises(VahrError, match="cannot connect to the MQTT broker"):
        room(thing="placebot1", environ={"VAHR_ROOM_BROKER": f"mqtt://127.0.0.1:{free_port()}"})


def test_the_device_voice_takes_its_commands_from_the_environment() -> None:
    voice = device(
        thing="placebot1",
        environ={"VAHR_PLAY_COMMAND": "sox -t wav - -d", "VAHR_RECORD_COMMAND": "sox -d -t raw -"},
    )
    assert isinstance(voice, DeviceVoice)
    assert voice.player == ["sox", "-t", "wav", "-", "-d"]
    assert voice.recorder == ["sox", "-d", "-t", "raw", "-"]


@pytest.mark.skipif(shutil.which("aplay") is not None, reason="alsa-utils is installed here")
def test_the_device_voice_without_alsa_utils_says_what_to_install() -> None:
    with pytest.raises(VoiceError, match="install alsa-utils"):
        device(thing="placebot1", environ={})


def test_lex_needs_its_settings(tmp_path: Path) -> None:
    env = {"VAHR_PLAY_COMMAND": "true", "VAHR_RECORD_COMMAND": "true", "VAHR_INTERPRETER": "lex"}
    with pytest.raises(VoiceError, match="certificate and key"):
        device(thing="placebot1", environ=env)
    cert, key = tmp_path / "c.pem", tmp_path / "k.pem"
    env |= {"VAHR_ROBOT_CERT": str(cert), "VAHR_ROBOT_KEY": str(key)}
    with pytest.raises(VoiceError, match="VAHR_IOT_CREDENTIALS_ENDPOINT"):
        device(thing="placebot1", environ=env)
    with pytest.raises(VoiceError, match="expected local or lex"):
        device(thing="placebot1", environ=env | {"VAHR_INTERPRETER": "oracle"})


def test_lex_is_chosen_with_the_robot_certificate(tmp_path: Path) -> None:
    from vahr.local.pki import LocalCA

    robot = LocalCA.load_or_create(tmp_path / "state").issue_client("placebot1", tmp_path / "r")
    env = {
        "VAHR_PLAY_COMMAND": "true", "VAHR_RECORD_COMMAND": "true", "VAHR_INTERPRETER": "lex",
        "VAHR_IOT_CREDENTIALS_ENDPOINT": "c1abc.credentials.iot.eu-west-1.amazonaws.com",
        "VAHR_LEX_BOT_ID": "BOTID12345", "VAHR_LEX_BOT_ALIAS_ID": "ALIAS12345",
        "VAHR_LEX_REGION": "eu-west-1",
    }  # fmt: skip
    config = AgentConfig(
        thing="placebot1", endpoint="x.iot.eu-west-1.amazonaws.com",
        cert=str(robot.cert_file), key=str(robot.key_file), ca=str(robot.ca_file),
    )  # fmt: skip
    voice = device(thing="placebot1", config=config, environ=env)
    lex = voice.understanding.interpreter
    assert isinstance(lex, LexInterpreter)
    assert (lex.bot_id, lex.bot_alias_id, lex.locale_id, lex.session_id, lex.region) == (
        "BOTID12345", "ALIAS12345", "en_US", "placebot1", "eu-west-1",
    )  # fmt: skip
