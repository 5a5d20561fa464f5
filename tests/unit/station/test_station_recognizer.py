"""The station's push-to-talk recognizer (`vahr.station.vocabulary.command_recognizer`):
its language model is made in a child process from the interaction model, kept in the
cache and read from it by the station itself at the next start, and the recognizer hears
real speech with it; a second start builds nothing."""

from __future__ import annotations

import json
import logging
from typing import TYPE_CHECKING

import pytest

from tests.support.push_to_talk import clip
from vahr.errors import VahrError
from vahr.speech.lm_stt import LanguageModelRecognizer
from vahr.station.vocabulary import command_model, command_recognizer, load_model, sentences
from vahr.station.voice import PushToTalk

if TYPE_CHECKING:
    from pathlib import Path

# An interaction model of one intent: small, so its model builds in a second.
MODEL = {
    "interactionModel": {
        "languageModel": {
            "invocationName": "robot fleet",
            "intents": [
                {
                    "name": "NavigateIntent",
                    "slots": [
                        {"name": "robot", "type": "ROBOT"},
                        {"name": "zone", "type": "ZONE"},
                    ],
                    "samples": ["send {robot} to {zone}", "move {robot} to {zone}"],
                },
                {"name": "AMAZON.StopIntent", "samples": []},
            ],
            "types": [
                {
                    "name": "ROBOT",
                    "values": [
                        {"name": {"value": "placebot 1", "synonyms": ["robot one"]}},
                        {"name": {"value": "placebot 2", "synonyms": ["robot two"]}},
                    ],
                },
                {
                    "name": "ZONE",
                    "values": [{"name": {"value": f"zone {z}"}} for z in "abcd"],
                },
            ],
        }
    }
}


@pytest.fixture
def model_file(tmp_path: Path) -> Path:
    file = tmp_path / "en-US.json"
    file.write_text(json.dumps(MODEL), encoding="utf-8")
    return file


def test_the_recognizer_from_the_child_process_is_the_one_built_here(
    model_file: Path, tmp_path: Path
) -> None:
    cache = tmp_path / "cache"
    recognizer = command_recognizer(model_file, cache_dir=cache)
    here = LanguageModelRecognizer(sentences(load_model(model_file)), nbest=True)
    assert recognizer.sentences == here.sentences
    assert recognizer.model == here.model
    assert "send placebot two to zone b" in recognizer.sentences
    heard = recognizer.recognize(clip("espeak-ng", "send placebot two to zone b"))
    assert heard.text == "send placebot two to zone b"
    assert heard.hypotheses


def test_a_second_start_reads_the_model_from_the_cache(model_file: Path, tmp_path: Path) -> None:
    cache = tmp_path / "cache"
    first = command_model(model_file, None, cache)
    assert not first.cached
    # The sentences written out and their language model, each kept
    written = {file.name: file.stat().st_mtime_ns for file in cache.iterdir()}
    assert sorted(name.split("-")[0] for name in written) == ["language", "sentences"]
    second = command_model(model_file, None, cache)
    assert second.cached
    assert (second.sentences, second.model) == (first.sentences, first.model)
    # The station's own start finds them too, and nothing is written again
    assert command_recognizer(model_file, cache_dir=cache).model == first.model
    assert {file.name: file.stat().st_mtime_ns for file in cache.iterdir()} == written


def test_the_station_reads_a_cached_model_itself_and_builds_a_missing_one_in_a_child(
    model_file: Path, tmp_path: Path, caplog: pytest.LogCaptureFixture
) -> None:
    cache = tmp_path / "cache"
    caplog.set_level(logging.INFO, logger="vahr.station.vocabulary")
    # A first start builds the model in a child process
    built = command_recognizer(model_file, cache_dir=cache)
    assert "language model built in a child process" in caplog.text
    # A second reads it from the cache in the station itself
    caplog.clear()
    assert command_recognizer(model_file, cache_dir=cache).model == built.model
    assert "language model read from the cache in" in caplog.text
    assert "child process" not in caplog.text
    # A damaged model is made again in a child process, the same model
    caplog.clear()
    [kept] = cache.glob("language-model-*.json")
    kept.write_text("{not json")
    assert command_recognizer(model_file, cache_dir=cache).model == built.model
    assert "language model built in a child process" in caplog.text


def test_a_damaged_list_of_sentences_is_written_out_again(model_file: Path, tmp_path: Path) -> None:
    cache = tmp_path / "cache"
    first = command_model(model_file, None, cache)
    [kept] = cache.glob("sentences-*.json")
    kept.write_text("{not json")
    again = command_model(model_file, None, cache)
    assert again.sentences == first.sentences and not again.cached
    assert command_model(model_file, None, cache).cached


def test_without_the_cache_nothing_is_kept(model_file: Path, tmp_path: Path) -> None:
    home = tmp_path / "cache-home"
    recognizer = command_recognizer(model_file, cache_dir=home, use_cache=False)
    assert "send placebot one to zone d" in recognizer.sentences
    assert not home.exists()


def test_an_unreadable_interaction_model_is_a_one_line_error(tmp_path: Path) -> None:
    missing = tmp_path / "nowhere.json"
    with pytest.raises(VahrError, match="cannot read the interaction model .*nowhere.json"):
        command_recognizer(missing, cache_dir=tmp_path)


def test_a_warm_up_that_fails_says_why_and_the_first_press_tries_again(
    tmp_path: Path, caplog: pytest.LogCaptureFixture
) -> None:
    missing = tmp_path / "nowhere.json"
    talk = PushToTalk(None, lambda: command_recognizer(missing, cache_dir=tmp_path))  # type: ignore[arg-type]
    warming = talk.warm_up()
    assert warming is not None
    warming.join(60)
    assert "the recognizer could not be built: cannot read the interaction model" in caplog.text
    with pytest.raises(VahrError, match="cannot read the interaction model"):
        talk.recognizer()


def test_another_interaction_model_is_written_out_anew(model_file: Path, tmp_path: Path) -> None:
    cache = tmp_path / "cache"
    command_model(model_file, None, cache)
    # Given the same model with a zone e, When it is loaded with the same cache
    grown = json.loads(model_file.read_text())
    zones = grown["interactionModel"]["languageModel"]["types"][1]["values"]
    zones.append({"name": {"value": "zone e"}})
    other = tmp_path / "grown.json"
    other.write_text(json.dumps(grown), encoding="utf-8")
    made = command_model(other, None, cache)
    # Then its sentences are its own, not the cached ones
    assert not made.cached and "send placebot two to zone e" in made.sentences
