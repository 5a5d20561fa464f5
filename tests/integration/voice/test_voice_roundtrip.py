"""Acceptance: espeak-ng speaks the assistant's answers, pocketsphinx and the local
interpreter understand every one, clean and with white noise at 20 dB SNR, in two voices;
silence and unrelated sentences come back unknown, with the reason; a robot's second start
hears with the language model its first one cached."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
import pytest

from vahr.speech.audio import SAMPLE_RATE, Audio, add_white_noise, concatenate
from vahr.speech.tts import EspeakSynthesizer

if TYPE_CHECKING:
    from pathlib import Path

    from robot_agent.voice.hearing import Hearing

VOICES = ("en-us+f2", "en-us+m3")
SUNNY = (
    "The weather is sunny.",
    "It is sunny today.",
    "The sun is shining.",
    "Today will be sunny.",
    "It is a sunny day.",
)
RAINY = ("The weather is rainy.", "It is raining.", "It will rain today.",
         "Today will be rainy.", "Bring an umbrella.")  # fmt: skip
UNRELATED = (
    "Please deliver the package to the loading zone.",
    "Thank you. It is sunny, so I am delivering to zone A.",
    "Robot two is stuck.",
)
ANSWERS = [(text, "sunny") for text in SUNNY] + [(text, "rainy") for text in RAINY]


@pytest.mark.parametrize("voice", VOICES)
@pytest.mark.parametrize("snr_db", [None, 20.0], ids=["clean", "snr20"])
def test_every_phrasing_is_understood(hearing: Hearing, voice: str, snr_db: float | None) -> None:
    # Given the answers spoken by espeak-ng at 16 kHz, with or without white noise
    tts = EspeakSynthesizer(voice)
    rng = np.random.default_rng(20)
    wrong = []
    for text, intent in ANSWERS:
        audio = tts.synthesize(text)
        assert len(audio.pcm) % 2 == 0 and audio.seconds > 0.3
        if snr_db is not None:
            audio = add_white_noise(audio, snr_db, rng)
        # When the robot hears them
        heard = hearing.hear(audio)
        # Then each is recognized and interpreted as its intent, with the posterior of the
        # words it rests on as the confidence
        if heard.intent != intent or not 0.0 < heard.confidence <= 1.0:
            wrong.append((text, heard))
    assert wrong == []


@pytest.mark.parametrize("voice", VOICES)
def test_silence_and_an_unrelated_sentence_are_unknown(hearing: Hearing, voice: str) -> None:
    tts = EspeakSynthesizer(voice)
    rng = np.random.default_rng(3)
    cases = {
        "silence": Audio.silence(2.0),
        "quiet room noise": add_white_noise(Audio.from_samples(np.full(SAMPLE_RATE, 20.0)), 0, rng),
    }
    for text in UNRELATED:
        cases[text] = tts.synthesize(text)
        cases[f"{text} (20 dB SNR)"] = add_white_noise(cases[text], 20.0, rng)
    heard = {name: hearing.hear(audio) for name, audio in cases.items()}
    # Then none is taken for an answer, each says why, and nothing is heard in silence
    assert {name: h.intent for name, h in heard.items()} == {name: "unknown" for name in cases}
    assert all(h.reason for h in heard.values())
    assert (heard["silence"].text, heard["silence"].reason) == ("", "no speech")


def test_a_sentence_after_the_answer_does_not_hide_it(hearing: Hearing) -> None:
    # Given the skill's answer followed by a second sentence after a pause
    tts = EspeakSynthesizer("en-us+f2")
    audio = concatenate(
        tts.synthesize("The weather is rainy."),
        Audio.silence(0.5),
        tts.synthesize("Is there anything else I can help with?"),
    )
    # Then the answer is still understood, and the rest heard as no weather
    heard = hearing.hear(audio)
    assert heard.intent == "rainy" and heard.evidence == ("rainy",)
    assert heard.text.startswith("the weather is rainy is there anything")


@pytest.mark.parametrize("voice", VOICES)
def test_the_room_assistant_hears_questions_and_ignores_other_robot_talk(voice: str) -> None:
    from vahr.local.room_assistant import QUESTIONS
    from vahr.speech.stt import GrammarRecognizer

    # Given the assistant's fast question recognizer (grammar, decoys, no phone loop)
    recognizer = GrammarRecognizer(QUESTIONS, verify=False)
    tts = EspeakSynthesizer(voice)
    rng = np.random.default_rng(11)
    asked = {
        "Alexa, ask robot fleet what the weather is": "alexa ask robot fleet what the weather is",
        "Alexa, ask robot fleet what is the weather": "alexa ask robot fleet what is the weather",
    }
    for spoken, text in asked.items():
        for audio in (tts.synthesize(spoken), add_white_noise(tts.synthesize(spoken), 20, rng)):
            heard = recognizer.recognize(audio)
            assert (heard.accepted, heard.text) == (True, text)
    for talk in ("Thank you. It is rainy, so I am delivering to zone C.",
                 "The weather is sunny.", "Robot two is stuck."):  # fmt: skip
        assert not recognizer.recognize(tts.synthesize(talk)).accepted, talk


def test_a_decode_that_fails_does_not_deafen_the_recognizer() -> None:
    from vahr.speech.stt import GrammarRecognizer, utterance

    # Given a recognizer whose decoder fails in the middle of an utterance (pocketsphinx
    # raises on an empty buffer, and a decoder left mid-utterance refuses every later search)
    recognizer = GrammarRecognizer(["it is sunny"], verify=False)
    decoder = recognizer._decoder
    decoder.activate_search("grammar")
    with pytest.raises(IndexError), utterance(decoder):
        decoder.process_raw(b"", full_utt=True)
    # Then the next clip is still heard
    heard = recognizer.recognize(EspeakSynthesizer("en-us+f2").synthesize("It is sunny."))
    assert (heard.accepted, heard.text) == (True, "it is sunny")


def test_a_robot_reads_its_hearing_from_the_model_cache_and_hears_the_same(
    tmp_path: Path,
) -> None:
    from robot_agent.voice.answers import WeatherAnswers
    from robot_agent.voice.hearing import weather_recognizer

    # Given a robot's first start, with an empty model cache
    answers = WeatherAnswers.load()
    built = weather_recognizer(answers, cache_dir=tmp_path)
    assert len(list(tmp_path.glob("language-model-*.json"))) == 1
    # When it starts again
    again = weather_recognizer(answers, cache_dir=tmp_path)
    # Then it hears with the model it built (nothing new in the cache), as it did
    assert len(list(tmp_path.glob("language-model-*.json"))) == 1
    assert again.model == built.model  # type: ignore[attr-defined]
    audio = EspeakSynthesizer("en-us+m3").synthesize("It will rain today.")
    assert again.recognize(audio) == built.recognize(audio)
    assert again.recognize(audio).text == "it will rain today"
