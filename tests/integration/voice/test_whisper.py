"""Whisper, push-to-talk's second ear, on this machine: its weights are checked before they
are loaded, and it writes a spoken command with the fleet's names as the skill spells them."""

from __future__ import annotations

import hashlib
from typing import TYPE_CHECKING, Any

import pytest

from tests.support.push_to_talk import clip
from vahr.domain.fleet import load_fleet
from vahr.speech.errors import SpeechError
from vahr.speech.whisper_stt import (
    MODEL_ENV,
    SHA256_ENV,
    WhisperTranscriber,
    check_weights,
    model_directory,
)
from vahr.station.vocabulary import whisper_prompt

if TYPE_CHECKING:
    from pathlib import Path


@pytest.fixture(scope="module")
def whisper() -> WhisperTranscriber:
    return WhisperTranscriber(whisper_prompt(load_fleet()))


def test_the_prompt_names_every_robot_and_zone_of_the_fleet() -> None:
    assert whisper_prompt(load_fleet()) == (
        "Robot fleet: send placebot one to zone A. Placebot two, go to the loading zone. "
        "Deliver to zone A, zone B, zone C or zone D."
    )


def test_a_command_in_a_voice_built_from_a_person_is_written_with_the_fleets_names(
    whisper: WhisperTranscriber,
) -> None:
    heard = whisper.transcribe(clip("flite:rms", "send placebot two to the loading zone"))
    assert heard.lower().rstrip(".") == "send placebot two to the loading zone"


class CountedPasses:
    """Whisper's CTranslate2 model, counting the decoding passes it is asked for."""

    def __init__(self, model: Any) -> None:
        self.model = model
        self.passes = 0

    def generate(self, *args: Any, **kwargs: Any) -> Any:
        self.passes += 1
        return self.model.generate(*args, **kwargs)

    def __getattr__(self, name: str) -> Any:
        return getattr(self.model, name)


def test_a_clip_is_decoded_once_and_written_alike_on_every_press(
    whisper: WhisperTranscriber, monkeypatch: pytest.MonkeyPatch
) -> None:
    # Given "zone b" in a voice on which timestamped decoding loops ("Zone B. Zone D. Zone D.
    # ..."), after which faster-whisper decoded again by sampling, up to six times
    counted = CountedPasses(whisper._model.model)
    monkeypatch.setattr(whisper._model, "model", counted)
    spoken = clip("flite:awb", "zone b")
    # When it is pressed three times
    heard = [whisper.transcribe(spoken) for _ in range(3)]
    # Then each press is one pass, written the same, and no loop
    assert counted.passes == 3
    assert len(set(heard)) == 1, heard
    assert len(heard[0].split()) <= 3, heard


def test_weights_that_are_not_tiny_ens_are_refused(tmp_path: Path) -> None:
    with pytest.raises(SpeechError, match="does not exist"):
        check_weights(tmp_path)
    (tmp_path / "model.bin").write_bytes(b"not the weights")
    with pytest.raises(SpeechError, match="is not tiny.en's"):
        check_weights(tmp_path)


def test_the_weights_come_from_the_setting_when_given(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setenv(MODEL_ENV, str(tmp_path))
    assert model_directory() == tmp_path
    with pytest.raises(SpeechError, match="is not tiny.en's"):
        (tmp_path / "model.bin").write_bytes(b"x")
        WhisperTranscriber("Robot fleet.")


def test_other_weights_load_only_with_their_own_hash_given(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    # Given another model's directory (here tiny.en's files beside a model.bin of other bytes)
    for name in ("config.json", "tokenizer.json", "vocabulary.txt"):
        (tmp_path / name).symlink_to(model_directory() / name)
    (tmp_path / "model.bin").write_bytes(b"a larger model")
    monkeypatch.setenv(MODEL_ENV, str(tmp_path))
    # Then without its hash it is refused as not tiny.en's, with a hash of other bytes too
    with pytest.raises(SpeechError, match="is not tiny.en's"):
        check_weights(model_directory())
    monkeypatch.setenv(SHA256_ENV, "0" * 64)
    with pytest.raises(SpeechError, match=f"does not have the SHA-256 in {SHA256_ENV}"):
        check_weights(model_directory())
    # And a setting that is no hash is named
    monkeypatch.setenv(SHA256_ENV, "small.en")
    with pytest.raises(SpeechError, match="is not a SHA-256"):
        check_weights(model_directory())
    # And with its own hash its weights pass the check
    monkeypatch.setenv(SHA256_ENV, hashlib.sha256(b"a larger model").hexdigest().upper())
    check_weights(model_directory())
