"""Time one spoken weather exchange, stage by stage, and over the room channel.

Stages: the robot synthesizes its question (espeak-ng), the assistant recognizes it
(pocketsphinx, question grammar), the assistant synthesizes the answer, the robot
recognizes the answer and interprets it. Then the whole exchange over a real mosquitto
(`RoomVoice.say` + `listen` against the room assistant). Also measured: how often answers
are understood, and how often unrelated speech is wrongly accepted.
Run: `.venv/bin/python bench/voice_roundtrip.py [--runs N]`.
"""

from __future__ import annotations

import argparse
import asyncio
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
from _results import median, percentile, write_section

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from robot_agent.voice.answers import WeatherAnswers  # noqa: E402
from robot_agent.voice.hearing import offline_hearing, weather_recognizer  # noqa: E402
from robot_agent.voice.interpreter import LocalInterpreter  # noqa: E402
from vahr.local.room_assistant import QUESTIONS  # noqa: E402
from vahr.speech.audio import add_white_noise  # noqa: E402
from vahr.speech.stt import GrammarRecognizer  # noqa: E402
from vahr.speech.tts import EspeakSynthesizer  # noqa: E402

QUESTION = "Alexa, ask robot fleet what the weather is"
ANSWER = "The weather is sunny."
PHRASINGS = {
    "sunny": ["The weather is sunny.", "It is sunny today.", "The sun is shining.",
              "Today will be sunny.", "It is a sunny day."],
    "rainy": ["The weather is rainy.", "It is raining.", "It will rain today.",
              "Today will be rainy.", "Bring an umbrella."],
}  # fmt: skip
UNRELATED = [
    "Please deliver the package to the loading zone.", "Hello there, how are you?",
    "I am going to zone B.", "What time is it?", "The battery is low.",
    "Thank you. It is sunny, so I am delivering to zone A.", "Stop right there.",
    "The weather is cloudy.", "It is snowing.", "Robot one has arrived in zone C.",
    "Robot two is stuck.", "The package is loaded.", "Good morning everyone.",
    "I cannot find the charger.", "It is a cloudy day.",
]  # fmt: skip
VOICES = ["en-us+f2", "en-us+m3"]


def timed(fn, *args):  # type: ignore[no-untyped-def]
    started = time.perf_counter()
    result = fn(*args)
    return result, (time.perf_counter() - started) * 1000


def stages(runs: int) -> dict[str, list[float]]:
    robot_tts, assistant_tts = EspeakSynthesizer("en-us+f2"), EspeakSynthesizer("en-us+f4")
    answers = WeatherAnswers.load()
    robot_stt = weather_recognizer(answers)
    assistant_stt = GrammarRecognizer(QUESTIONS, verify=False)
    interpreter = LocalInterpreter(answers)
    times: dict[str, list[float]] = {k: [] for k in
        ("robot TTS (question)", "assistant STT (question)", "assistant TTS (answer)",
         "robot STT (answer)", "interpret", "exchange")}  # fmt: skip
    for _ in range(runs):
        question, t1 = timed(robot_tts.synthesize, QUESTION)
        heard_q, t2 = timed(assistant_stt.recognize, question)
        answer, t3 = timed(assistant_tts.synthesize, ANSWER)
        heard_a, t4 = timed(robot_stt.recognize, answer)
        meaning, t5 = timed(interpreter.interpret, heard_a.text)
        assert heard_q.accepted and meaning.intent == "sunny", (heard_q, heard_a, meaning)
        for key, value in zip(times, (t1, t2, t3, t4, t5, t1 + t2 + t3 + t4 + t5), strict=True):
            times[key].append(value)
    return times


def room_round_trip(runs: int) -> list[float]:
    from robot_agent.config import AgentConfig
    from robot_agent.voice.factories import room
    from vahr.local.room_assistant import offline_room_assistant
    from vahr.plumbing.mqtt import MqttClient, MqttEndpoint
    from vahr.plumbing.ports import free_port
    from vahr.twin.broker import BrokerConfig, Mosquitto

    with tempfile.TemporaryDirectory() as state:
        port = free_port()
        broker = Mosquitto(BrokerConfig(state_dir=Path(state), plain_port=port))
        broker.start()
        client = MqttClient(MqttEndpoint(port=port)).connect()
        assistant = offline_room_assistant(client, lambda _utterance: ANSWER).start()
        robot_link = MqttClient(MqttEndpoint(port=port)).connect()
        voice = room(thing="placebot1", config=AgentConfig(thing="placebot1"), link=robot_link)
        try:

            async def exchanges() -> list[float]:
                spent = []
                for _ in range(runs):
                    started = time.perf_counter()
                    await voice.say(QUESTION)
                    heard = await voice.listen(10.0)
                    spent.append((time.perf_counter() - started) * 1000)
                    assert heard.intent == "sunny", heard
                return spent

            return asyncio.run(exchanges())
        finally:
            robot_link.stop()
            assistant.stop()
            client.stop()
            broker.stop()


def accuracy() -> tuple[str, int, int, list[str]]:
    hearing = offline_hearing()
    rng = np.random.default_rng(8)
    rows, accepted, total, wrongly = [], 0, 0, []
    for voice in VOICES:
        tts = EspeakSynthesizer(voice)
        for snr in (None, 20.0):
            right = count = 0
            for intent, texts in PHRASINGS.items():
                for text in texts:
                    audio = tts.synthesize(text)
                    if snr is not None:
                        audio = add_white_noise(audio, snr, rng)
                    count += 1
                    right += hearing.hear(audio).intent == intent
            for text in UNRELATED:
                audio = tts.synthesize(text)
                if snr is not None:
                    audio = add_white_noise(audio, snr, rng)
                total += 1
                heard = hearing.hear(audio)
                if heard.intent != "unknown":
                    accepted += 1
                    wrongly.append(f"{text!r} ({voice}, {'clean' if snr is None else '20 dB'})")
            label = "clean" if snr is None else "20 dB SNR"
            rows.append(f"| {voice} | {label} | {right}/{count} |")
    return "\n".join(rows), accepted, total, wrongly


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--runs", type=int, default=15)
    args = parser.parse_args()
    times = stages(args.runs)
    room_ms = room_round_trip(max(5, args.runs // 2))
    rows, false_accepts, unrelated, wrongly = accuracy()
    table = "\n".join(
        f"| {stage} | {median(v):.0f} | {percentile(v, 90):.0f} |" for stage, v in times.items()
    )
    room = f"{median(room_ms):.0f} | {percentile(room_ms, 90):.0f}"
    body = f"""
One weather exchange, {args.runs} runs (milliseconds; target: exchange at most 1000 ms).

| stage | median | p90 |
| --- | ---: | ---: |
{table}
| room channel round trip (say + listen over mosquitto, {len(room_ms)} runs) | {room} |

The room round trip includes both syntheses, both recognitions, the interpretation and
four MQTT hops with base64 WAV payloads; the robot's `listen` starts after `say` returns.

Answers understood (5 sunny + 5 rainy phrasings, espeak-ng at 16 kHz):

| voice | audio | understood |
| --- | --- | ---: |
{rows}

Unrelated sentences wrongly accepted as an answer: {false_accepts} of {unrelated}
({len(UNRELATED)} sentences, two voices, clean and at 20 dB SNR).
{"Accepted: " + "; ".join(wrongly) + "." if wrongly else ""}
"""
    write_section("voice_roundtrip", "Voice round trip (robot to assistant and back)", body)


if __name__ == "__main__":
    main()
