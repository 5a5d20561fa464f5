"""Voice factories for `robot-agent run --voice MODULE:FACTORY`.

`robot_agent.voice.factories:room` speaks over the local stack's room channel, on the
agent's own link; `robot_agent.voice.factories:device` uses the robot's own speaker and
microphone. Each is called once at start-up with the thing name, the agent's configuration
(whose `voice` section holds every voice setting, environment variables included: see
`robot_agent.config.ENVIRONMENT`) and, for the room, the agent's link.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

from vahr.speech.errors import SpeechError

if TYPE_CHECKING:
    from robot_agent.config import AgentConfig
    from robot_agent.voice.devices import DeviceVoice
    from robot_agent.voice.hearing import Hearing
    from robot_agent.voice.room import RoomVoice
    from vahr.protocol.link import Link
    from vahr.speech.tts import Synthesizer


def synthesizer_for(config: AgentConfig) -> Synthesizer:
    """The configured synthesizer: an espeak-ng voice, or `polly:VOICE`, `gtts[:LANG]`."""
    from vahr.speech.tts import make_synthesizer

    spec = config.voice.synthesizer
    return make_synthesizer(spec if ":" in spec or spec in ("polly", "gtts") else f"espeak:{spec}")


def hearing_for(thing: str, config: AgentConfig) -> Hearing:
    """pocketsphinx, then the local interpreter or Lex as `voice.interpreter` says."""
    from robot_agent.voice.answers import WeatherAnswers
    from robot_agent.voice.hearing import (
        Hearing,
        offline_hearing,
        weather_recognizer,
    )

    if config.voice.interpreter == "local":
        return offline_hearing()
    from robot_agent.voice.iot_credentials import IotCredentialsProvider
    from robot_agent.voice.lex import LexInterpreter

    lex = config.voice.lex
    cert, key = lex.cert or config.cert, lex.key or config.key
    if not cert or not key:
        raise SpeechError("VAHR_INTERPRETER=lex needs the robot's certificate and key")
    for value, variable in (
        (lex.credentials_endpoint, "VAHR_IOT_CREDENTIALS_ENDPOINT"),
        (lex.bot_id, "VAHR_LEX_BOT_ID"),
        (lex.bot_alias_id, "VAHR_LEX_BOT_ALIAS_ID"),
        (lex.region, "VAHR_LEX_REGION (or AWS_REGION)"),
    ):
        if not value:
            raise SpeechError(f"VAHR_INTERPRETER=lex needs {variable}")
    ca = lex.ca or config.ca
    provider = IotCredentialsProvider(
        endpoint=str(lex.credentials_endpoint),
        role_alias=lex.role_alias,
        thing=thing,
        cert=Path(cert),
        key=Path(key),
        ca=Path(ca) if ca else None,
    )
    interpreter = LexInterpreter(
        bot_id=str(lex.bot_id),
        bot_alias_id=str(lex.bot_alias_id),
        locale_id=lex.locale_id,
        session_id=thing,
        region=str(lex.region),
        credentials=provider.get,
        endpoint_url=lex.endpoint_url,
    )
    return Hearing(weather_recognizer(WeatherAnswers.load()), interpreter)


def room(*, thing: str, config: AgentConfig, link: Link) -> RoomVoice:
    """A `RoomVoice` speaking over the agent's own link (one connection per robot)."""
    from robot_agent.voice.room import RoomVoice

    return RoomVoice(thing, link, synthesizer_for(config), hearing_for(thing, config))


def device(*, thing: str, config: AgentConfig) -> DeviceVoice:
    """A `DeviceVoice` on the default sound card (aplay/arecord unless configured)."""
    from robot_agent.voice.devices import DeviceVoice, default_player, default_recorder

    voice = config.voice
    return DeviceVoice(
        synthesizer_for(config),
        hearing_for(thing, config),
        player=voice.play_command or default_player(),
        recorder=voice.record_command or default_recorder(),
        settings=voice.listen,
    )
