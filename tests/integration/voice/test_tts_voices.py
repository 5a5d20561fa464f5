"""The offline voices the hearing is evaluated with: each engine speaks, by its one name,
and a voice that does not exist is refused in one line."""

from __future__ import annotations

from typing import TYPE_CHECKING

import pytest

from robot_agent.voice.evaluation import Phrasings, render, synthesizer_for_voice
from vahr.speech.errors import SpeechError
from vahr.speech.tts import engine_of, make_synthesizer, voice_names

if TYPE_CHECKING:
    from pathlib import Path


@pytest.mark.parametrize(
    "voice", ["espeak-ng:en-us+f2", "flite:slt", "flite:kal", "festival:cmu_us_slt_arctic_hts"]
)
def test_each_engine_speaks_a_command_as_16_khz_audio(voice: str) -> None:
    audio = make_synthesizer(voice).synthesize("send placebot one to zone b")
    # A five-word command takes one to four seconds in every voice.
    assert 1.0 < audio.seconds < 4.0
    assert audio.samples().std() > 100  # not silence


def test_every_listed_voice_names_its_engine() -> None:
    for engine, voices in voice_names().items():
        assert voices
        assert {engine_of(voice) for voice in voices} == {engine}


@pytest.mark.parametrize(
    ("voice", "says"),
    [
        ("flite:nobody", "flite voice 'nobody'"),
        ("festival:nobody", "unbound variable"),
        ("festival:x)(y", "not a voice name"),
        ("klatt:one", "unknown synthesizer"),
    ],
)
def test_an_unknown_voice_is_refused_in_one_line(voice: str, says: str) -> None:
    with pytest.raises(SpeechError) as caught:
        make_synthesizer(voice).synthesize("zone b")
    assert says in str(caught.value)
    assert "\n" not in str(caught.value)


def test_the_robots_evaluation_sets_name_voices_of_any_engine(tmp_path: Path) -> None:
    phrasings = Phrasings(
        voices=["en-us+f4", "flite:kal"],
        snr_db=[],
        seed=1,
        answers={"sunny": ["it is sunny"]},
        unrelated=["open the door"],
    )
    manifest = render(phrasings, tmp_path, synthesizer_for_voice)
    assert sorted({clip.voice for clip in manifest.clips}) == ["en-us+f4", "flite:kal"]
    # The same file renders the same audio again, whichever engine spoke it.
    again = render(phrasings, tmp_path / "again", synthesizer_for_voice)
    assert again.digest() == manifest.digest()
