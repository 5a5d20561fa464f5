"""How an evaluation set is rendered (`robot_agent.voice.evaluation.render`): every sentence
in every voice and condition, or with `voices_in_turn` each sentence in one voice, the voices
taken in turn, and the noise of a clip the same in either."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from robot_agent.voice.evaluation import Phrasings, render
from vahr.speech.audio import Audio

if TYPE_CHECKING:
    from pathlib import Path

PHRASINGS = Phrasings(
    voices=["low", "high"],
    snr_db=[10.0],
    seed=7,
    answers={"sunny": ["sunny all day", "clear skies"], "rainy": ["rain later"]},
    unrelated=["what time is it"],
)


class Tone:
    """A synthesizer that says anything as one second of a tone of its voice's pitch."""

    def __init__(self, voice: str) -> None:
        self.hertz = {"low": 220.0, "high": 440.0}[voice]

    def synthesize(self, text: str) -> Audio:
        seconds = np.arange(16_000) / 16_000
        return Audio.from_samples(np.sin(2 * np.pi * self.hertz * seconds) * 8000)


def test_every_sentence_is_rendered_in_every_voice_and_condition(tmp_path: Path) -> None:
    manifest = render(PHRASINGS, tmp_path, Tone)
    assert len(manifest.clips) == 4 * 2 * 2
    assert all((tmp_path / clip.file).is_file() for clip in manifest.clips)


def test_voices_in_turn_speak_each_sentence_once_per_condition(tmp_path: Path) -> None:
    # When the set is rendered with its voices in turn
    turns = render(PHRASINGS, tmp_path / "turns", Tone, voices_in_turn=True)
    # Then each sentence is spoken once per condition, every voice speaking some
    spoken = {(clip.text, clip.condition) for clip in turns.clips}
    assert len(turns.clips) == len(spoken) == 4 * 2
    assert {clip.voice for clip in turns.clips} == {"low", "high"}
    # And each clip is the one the whole set has for that voice, sentence and condition
    whole = {clip.file: clip.sha256 for clip in render(PHRASINGS, tmp_path / "all", Tone).clips}
    assert all(whole[clip.file] == clip.sha256 for clip in turns.clips)
