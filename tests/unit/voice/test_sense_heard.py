"""The sense check's training sentences as heard: every sentence spoken clean and in noise,
what was heard kept once, and no held-out sentence among what is written."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
import yaml

from robot_agent.voice.sense_heard import CONDITIONS, HEARD_VOICES, heard_texts, write_heard
from vahr.speech.audio import Audio

if TYPE_CHECKING:
    from pathlib import Path


def test_every_sentence_is_heard_clean_and_in_noise_in_the_voices_in_turn() -> None:
    spoken: list[tuple[str, str]] = []
    heard: list[int] = []

    def speak(voice: str, text: str) -> Audio:
        spoken.append((voice, text))
        return Audio.from_samples(np.ones(1600) * 1000.0)

    def hear(audio: Audio) -> str:
        heard.append(len(audio.samples()))
        # The clean clip is heard right, a noisy one as another sentence
        return "It is SUNNY." if float(np.std(audio.samples())) == 0.0 else "it is funny"

    texts = heard_texts(["it is sunny", "bright and dry"], speak, hear)
    assert spoken == [(HEARD_VOICES[0], "it is sunny"), (HEARD_VOICES[1], "bright and dry")]
    assert len(heard) == 2 * len(CONDITIONS)
    assert texts == ["it is sunny", "it is funny"]


def test_held_out_sentences_are_not_written(tmp_path: Path) -> None:
    path = tmp_path / "heard.yaml"
    counts = write_heard(
        path, ["it is sunny", "sunny all day"], ["a rainy day fund"], {"it is sunny"}
    )
    assert counts == (1, 1)
    assert yaml.safe_load(path.read_text()) == {
        "answers": ["sunny all day"],
        "other": ["a rainy day fund"],
    }
