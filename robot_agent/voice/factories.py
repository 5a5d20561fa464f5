"""Voice factories for `robot-agent run --voice MODULE:FACTORY`.

`robot_agent.voice.factories:room` speaks over the local stack's room channel;
`robot_agent.voice.factories:device` uses the robot's own speaker and microphone. Each is
called once at start-up with the thing name (and, when the caller has it, the agent's
configuration, whose broker or mTLS settings the room channel reuses). Environment
variables are read here, once, for what the configuration does not carry:

- VAHR_ROOM_BROKER: `mqtt://127.0.0.1:PORT` for the room channel (default: the agent's
  `--broker`); with the agent's mTLS settings instead, its endpoint and certificate.
- VAHR_VOICE: the espeak-ng voice (default en-us+f2), or `polly:VOICE`.
- VAHR_PLAY_COMMAND / VAHR_RECORD_COMMAND: the device's player and recorder commands.
- VAHR_INTERPRETER: `local` (default) or `lex`; for Lex, VAHR_LEX_BOT_ID,
  VAHR_LEX_BOT_ALIAS_ID, VAHR_LEX_LOCALE (en_US), VAHR_LEX_REGION (else AWS_REGION), and
  the IoT credentials provider: VAHR_IOT_CREDENTIALS_ENDPOINT, VAHR_IOT_ROLE_ALIAS
  (vahr-robot-lex), with the robot's certificate from the agent's config (--cert, --key,
  --ca) or VAHR_ROBOT_CERT, VAHR_ROBOT_KEY, VAHR_ROBOT_CA.
"""

from __future__ import annotations

import os
import shlex
from pathlib import Path
from typing import TYPE_CHECKING, Any
from urllib.parse import urlsplit

from robot_agent.voice.port import VoiceError

if TYPE_CHECKING:
    from collections.abc import Mapping

    from robot_agent.voice.devices import DeviceVoice
    from robot_agent.voice.room import RoomVoice
    from robot_agent.voice.understanding import Understanding


def _synthesizer(environ: Mapping[str, str]) -> Any:
    from robot_agent.voice.tts import DEFAULT_VOICE, make_synthesizer

    spec = environ.get("VAHR_VOICE", DEFAULT_VOICE)
    return make_synthesizer(spec if ":" in spec else f"espeak:{spec}")


def understanding_for(thing: str, config: Any, environ: Mapping[str, str]) -> Understanding:
    """pocketsphinx, then the local interpreter or Lex as VAHR_INTERPRETER says."""
    from robot_agent.voice.answers import WeatherAnswers
    from robot_agent.voice.stt import GrammarRecognizer
    from robot_agent.voice.understanding import Understanding, offline_understanding

    choice = environ.get("VAHR_INTERPRETER", "local")
    if choice == "local":
        return offline_understanding()
    if choice != "lex":
        raise VoiceError(f"VAHR_INTERPRETER={choice!r}: expected local or lex")
    from robot_agent.voice.iot_credentials import IotCredentialsProvider
    from robot_agent.voice.lex import LexInterpreter

    def need(name: str) -> str:
        value = environ.get(name)
        if not value:
            raise VoiceError(f"VAHR_INTERPRETER=lex needs {name}")
        return value

    def robot_file(env_name: str, attribute: str) -> Path | None:
        value = environ.get(env_name) or getattr(config, attribute, None)
        return Path(value) if value else None

    cert, key = robot_file("VAHR_ROBOT_CERT", "cert"), robot_file("VAHR_ROBOT_KEY", "key")
    if cert is None or key is None:
        raise VoiceError("VAHR_INTERPRETER=lex needs the robot's certificate and key")
    provider = IotCredentialsProvider(
        endpoint=need("VAHR_IOT_CREDENTIALS_ENDPOINT"),
        role_alias=environ.get("VAHR_IOT_ROLE_ALIAS", "vahr-robot-lex"),
        thing=thing,
        cert=cert,
        key=key,
        ca=robot_file("VAHR_ROBOT_CA", "ca"),
    )
    region = environ.get("VAHR_LEX_REGION") or environ.get("AWS_REGION")
    if not region:
        raise VoiceError("VAHR_INTERPRETER=lex needs VAHR_LEX_REGION (or AWS_REGION)")
    lex = LexInterpreter(
        bot_id=need("VAHR_LEX_BOT_ID"),
        bot_alias_id=need("VAHR_LEX_BOT_ALIAS_ID"),
        locale_id=environ.get("VAHR_LEX_LOCALE", "en_US"),
        session_id=thing,
        region=region,
        credentials=provider.get,
        endpoint_url=environ.get("VAHR_LEX_ENDPOINT_URL"),
    )
    return Understanding(GrammarRecognizer(WeatherAnswers.load().all_phrases()), lex)


def room(*, thing: str, config: Any = None, environ: Mapping[str, str] | None = None) -> RoomVoice:
    """A `RoomVoice` on its own MQTT connection to the local broker."""
    from robot_agent.voice.room import RoomVoice
    from vahr.local.mqtt import MqttClient, MqttEndpoint
    from vahr.local.pki import ClientCredentials

    env = os.environ if environ is None else environ
    broker = env.get("VAHR_ROOM_BROKER") or getattr(config, "broker", None)
    if broker:
        url = urlsplit(broker)
        if url.scheme != "mqtt" or url.port is None:
            raise VoiceError(f"room broker {broker!r}: expected mqtt://HOST:PORT")
        endpoint = MqttEndpoint(host=url.hostname or "127.0.0.1", port=url.port)
    elif config is not None and getattr(config, "endpoint", None) and config.ca:
        endpoint = MqttEndpoint(
            host=str(config.endpoint),
            port=int(config.port),
            credentials=ClientCredentials(
                cert_file=Path(config.cert), key_file=Path(config.key), ca_file=Path(config.ca)
            ),
        )
    else:
        raise VoiceError("the room voice needs VAHR_ROOM_BROKER=mqtt://HOST:PORT or --broker")
    # Its own client id: the agent's link holds the thing name as client id.
    client = MqttClient(endpoint, client_id=f"{thing}-voice").connect()
    try:
        return RoomVoice(
            thing,
            client,
            _synthesizer(env),
            understanding_for(thing, config, env),
            on_close=client.stop,
        )
    except BaseException:
        client.stop()
        raise


def device(
    *, thing: str, config: Any = None, environ: Mapping[str, str] | None = None
) -> DeviceVoice:
    """A `DeviceVoice` on the default sound card (aplay/arecord unless overridden)."""
    from robot_agent.voice.devices import DeviceVoice, default_player, default_recorder

    env = os.environ if environ is None else environ
    play = env.get("VAHR_PLAY_COMMAND")
    record = env.get("VAHR_RECORD_COMMAND")
    return DeviceVoice(
        _synthesizer(env),
        understanding_for(thing, config, env),
        player=shlex.split(play) if play else default_player(),
        recorder=shlex.split(record) if record else default_recorder(),
    )
