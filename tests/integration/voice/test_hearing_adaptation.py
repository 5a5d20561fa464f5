"""The hearing's acoustic adaptation (robot_agent/voice/adaptation.py): sphinxtrain adapts the
model to spoken sentences (MAP parameters or an MLLR transform), the recognizers load it,
and it is chosen by `VAHR_HEARING_ADAPTATION`."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from pocketsphinx import get_model_path

from robot_agent.voice.adaptation import (
    _SENDUMP_LOG_STEP,
    BUNDLED,
    VOICES,
    adapt,
    adaptation_sentences,
    synthesized_clips,
    write_mixture_weights,
)
from robot_agent.voice.answers import WeatherAnswers
from robot_agent.voice.evaluation import EVALUATION_SET, TUNING_SET, Phrasings
from robot_agent.voice.hearing import Hearing, hearing_adaptation
from robot_agent.voice.interpreter import LocalInterpreter
from vahr.speech.errors import SpeechError
from vahr.speech.lm_stt import LanguageModelRecognizer
from vahr.speech.stt import GrammarRecognizer
from vahr.speech.tts import EspeakSynthesizer

SENDUMP = Path(get_model_path()) / "en-us" / "en-us" / "sendump"


def test_expanded_mixture_weights_quantize_back_to_the_models_own(tmp_path: Path) -> None:
    # Given pocketsphinx's quantized mixture weights expanded for sphinxtrain
    out = tmp_path / "mixture_weights"
    write_mixture_weights(SENDUMP, out)
    # When they are read back and quantized the way pocketsphinx does
    data = out.read_bytes()
    start = data.index(b"endhdr\n") + len(b"endhdr\n") + 4
    senones, streams, densities, size = np.frombuffer(data, "<i4", count=4, offset=start)
    weights = np.frombuffer(data, "<f4", offset=start + 16).reshape(senones, streams, densities)
    levels = np.minimum(np.rint(-np.log(weights) / _SENDUMP_LOG_STEP), 255)
    # Then each is within one quantization step of the model's, and each distribution sums to 1
    original = np.frombuffer(SENDUMP.read_bytes()[-size:], np.uint8)
    original = original.reshape(streams, densities, senones).transpose(2, 0, 1)
    assert size == weights.size == 5126 * 3 * 128
    assert np.abs(levels - original).max() <= 1
    assert np.allclose(weights.sum(axis=2), 1.0, atol=1e-4)


@pytest.mark.slow
def test_an_adaptation_estimated_from_speech_is_heard_with(tmp_path: Path) -> None:
    # Given a few of the answers spoken clean in one voice
    answers = WeatherAnswers.load()
    sentences = sorted(answers.all_phrases())[:12]
    clips = list(synthesized_clips(sentences, voices=["en-us+m2"], snr_db=[]))
    # When sphinxtrain adapts the model to them, by MAP and by MLLR
    parameters, again = tmp_path / "voice", tmp_path / "again"
    transform = tmp_path / "voice.mllr"
    used = adapt(clips, parameters)
    adapt(clips, again)
    adapt(clips, transform, method="mllr")
    # Then every clip was used, MAP wrote the parameters the decoder loads (the same bytes
    # each time) and MLLR one transform, and a hearing adapted either way still understands
    # the skill's answer
    assert used == 12
    names = ["means", "sendump", "transition_matrices", "variances"]
    assert sorted(p.name for p in parameters.iterdir()) == names
    assert all((parameters / n).read_bytes() == (again / n).read_bytes() for n in names)
    assert transform.read_text().split()[:3] == ["1", "3", "13"]  # one class, three streams
    answer = EspeakSynthesizer(voice="en-us+f2").synthesize("The weather is sunny.")
    for adaptation in (parameters, transform):
        exact = GrammarRecognizer(answers.all_phrases(), adaptation=adaptation)
        assert exact.recognize(answer).text == "the weather is sunny"
        wider = LanguageModelRecognizer(answers.corpus(), adaptation=adaptation)
        hearing = Hearing(wider, LocalInterpreter(answers))
        assert hearing.hear(answer).intent == "sunny"


def test_the_bundled_adaptation_knows_no_evaluation_voice_or_sentence() -> None:
    tuning = Phrasings.load(TUNING_SET)
    evaluation = Phrasings.load(EVALUATION_SET)
    assert not set(VOICES) & (set(evaluation.voices) | set(tuning.voices))
    sentences = set(adaptation_sentences())
    assert len(sentences) > 500
    assert not sentences & (evaluation.normalized() | tuning.normalized())


def test_clips_no_word_of_which_is_known_are_refused(tmp_path: Path) -> None:
    clips = synthesized_clips(["zorblax quenfid"], voices=["en-us+m2"], snr_db=[])
    with pytest.raises(SpeechError, match="no clip to adapt on"):
        adapt(clips, tmp_path / "voice.mllr")
    assert not (tmp_path / "voice.mllr").exists()


def test_the_setting_chooses_the_adaptation(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv("VAHR_HEARING_ADAPTATION", raising=False)
    assert hearing_adaptation() == BUNDLED and (BUNDLED / "means").is_file()
    assert hearing_adaptation("espeak-ng") == BUNDLED
    assert hearing_adaptation("none") is None
    monkeypatch.setenv("VAHR_HEARING_ADAPTATION", "/srv/alexa.mllr")
    assert hearing_adaptation() == Path("/srv/alexa.mllr")


def test_a_missing_transform_is_a_one_line_error(tmp_path: Path) -> None:
    with pytest.raises(SpeechError, match="no acoustic adaptation at .*absent.mllr"):
        GrammarRecognizer(["it is sunny"], adaptation=tmp_path / "absent.mllr")


def test_an_adaptation_folder_without_parameters_is_a_one_line_error(tmp_path: Path) -> None:
    with pytest.raises(SpeechError, match="no adapted parameters"):
        LanguageModelRecognizer(["it is sunny"], adaptation=tmp_path)


def test_an_unknown_method_is_refused(tmp_path: Path) -> None:
    with pytest.raises(SpeechError, match="unknown adaptation method 'fmllr'"):
        adapt([], tmp_path / "voice", method="fmllr")
