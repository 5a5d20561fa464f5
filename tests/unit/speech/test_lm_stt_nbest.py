"""The open recognizer's N best on the shortest speech: pocketsphinx's A* search runs out of
paths on a clip of one syllable, and the recognizer must answer with what it found rather
than fail (push-to-talk answered such a press with an error)."""

from __future__ import annotations

from tests.support.push_to_talk import clip
from vahr.station.vocabulary import command_recognizer


def test_a_clip_of_one_syllable_is_heard_with_the_paths_there_are() -> None:
    recognizer = command_recognizer()
    # festival's "b" leaves the lattice three distinct paths where it is asked for forty
    recognition = recognizer.recognize(clip("festival:cmu_us_slt_arctic_hts", "b"))
    assert 1 <= len(recognition.hypotheses) < 10
    assert recognition.hypotheses[0].text == recognition.text
