"""The recognizer's language model built in a child process and kept in a cache
(`vahr.speech.lm_stt`): the child's model is the very text this process builds, a cache hit
builds nothing, and a damaged or unreadable cache file is built again, never an error."""

from __future__ import annotations

import io
from typing import TYPE_CHECKING

import pytest

from vahr.speech import lm_stt
from vahr.speech.errors import SpeechError
from vahr.speech.lm_stt import (
    DISCOUNT_MASS,
    LanguageModel,
    build_language_model,
    cached_language_model,
    in_child_process,
)

if TYPE_CHECKING:
    from pathlib import Path

# "placebot" is in no dictionary: its pronunciations are guessed (espeak-ng, compounds).
SENTENCES = [
    "send placebot one to zone a",
    "send placebot two to zone b",
    "where is placebot one",
    "stop all robots",
]


def cache_file(folder: Path) -> Path:
    [file] = folder.glob("language-model-*.json")
    return file


def test_the_model_built_in_a_child_process_is_the_one_built_here() -> None:
    here = build_language_model(SENTENCES)
    there = in_child_process(build_language_model, SENTENCES)
    assert isinstance(there, LanguageModel)
    assert there.arpa == here.arpa
    assert there.dictionary == here.dictionary
    assert "\\3-grams:" in here.arpa
    assert here.words == {word for sentence in SENTENCES for word in sentence.split()}


def test_the_model_is_pocketsphinxs_own_arpabolm_to_the_byte() -> None:
    # Given the default interaction model's samples, normalized (thousands of sentences
    # sharing their words), and sentences with parentheses, which ArpaBoLM reads itself
    from pocketsphinx.lm import ArpaBoLM

    from vahr.domain.text import normalize
    from vahr.station.vocabulary import load_model

    intents = load_model()["interactionModel"]["languageModel"]["intents"]
    corpus = [normalize(sample) for intent in intents for sample in intent.get("samples", [])]
    assert len(corpus) > 1000
    for examples in (corpus, [*SENTENCES, "stop placebot one (utterance 7)"]):
        # When the model is built, and ArpaBoLM reads the same text (each sentence once)
        text = "\n".join(dict.fromkeys(examples))
        library = ArpaBoLM(text=text, add_start=True, discount_mass=DISCOUNT_MASS)
        library.compute()
        written = io.StringIO()
        library.write(written)
        # Then both are the same text
        assert lm_stt.arpa_model(examples) == written.getvalue()


def test_an_error_in_the_child_process_is_raised_here() -> None:
    with pytest.raises(SpeechError, match="at least one sentence"):
        in_child_process(build_language_model, ["", "  "])


def test_a_cache_hit_builds_nothing(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    built, cached = cached_language_model(SENTENCES, cache_dir=tmp_path)
    assert not cached
    file = cache_file(tmp_path)
    written = file.stat().st_mtime_ns

    def no_building(*_: object) -> str:
        raise AssertionError("the model was built again")

    monkeypatch.setattr(lm_stt, "arpa_model", no_building)
    again, cached = cached_language_model(SENTENCES, cache_dir=tmp_path)
    assert cached
    assert again == built
    assert file.stat().st_mtime_ns == written
    assert list(tmp_path.iterdir()) == [file]


def test_other_sentences_or_background_words_are_another_model(tmp_path: Path) -> None:
    first, _ = cached_language_model(SENTENCES, cache_dir=tmp_path)
    other, cached = cached_language_model(
        [*SENTENCES, "send placebot one home"], cache_dir=tmp_path
    )
    assert not cached
    assert other != first
    _, cached = cached_language_model(SENTENCES, 20, cache_dir=tmp_path)
    assert not cached
    assert len(list(tmp_path.glob("language-model-*.json"))) == 3


@pytest.mark.parametrize(
    "damage",
    [
        pytest.param(lambda text: text[: len(text) // 2], id="cut short"),
        pytest.param(lambda text: b"\x00\xff not json", id="not json"),
        pytest.param(lambda text: b'{"key": 1}', id="another shape"),
        # Still valid JSON of the right shape: only the digest tells.
        pytest.param(lambda text: text.replace(b"zone", b"zoom", 1), id="a word changed"),
    ],
)
def test_a_damaged_cache_file_is_built_again(tmp_path: Path, damage: object) -> None:
    built, _ = cached_language_model(SENTENCES, cache_dir=tmp_path)
    file = cache_file(tmp_path)
    file.write_bytes(damage(file.read_bytes()))  # type: ignore[operator]
    rebuilt, cached = cached_language_model(SENTENCES, cache_dir=tmp_path)
    assert not cached
    assert rebuilt == built
    # ... and written again whole: the next start reads it.
    assert cached_language_model(SENTENCES, cache_dir=tmp_path) == (built, True)


def test_an_unreadable_cache_is_skipped(tmp_path: Path) -> None:
    built, _ = cached_language_model(SENTENCES, cache_dir=tmp_path / "first")
    # A folder where the file should be: it can be neither read nor replaced.
    name = cache_file(tmp_path / "first").name
    (tmp_path / "second" / name).mkdir(parents=True)
    for _ in range(2):
        model, cached = cached_language_model(SENTENCES, cache_dir=tmp_path / "second")
        assert (model, cached) == (built, False)
    # A cache folder that cannot be made (a file is in its way) is skipped too.
    (tmp_path / "blocked").write_text("a file")
    assert cached_language_model(SENTENCES, cache_dir=tmp_path / "blocked") == (built, False)


def test_without_a_cache_folder_the_model_is_built_each_time(tmp_path: Path) -> None:
    model, cached = cached_language_model(SENTENCES, cache_dir=None)
    assert (model, cached) == (build_language_model(SENTENCES), False)


def test_the_cache_keeps_only_the_newest_models(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(lm_stt, "MODELS_KEPT", 2)
    files: list[Path] = []
    for number in ("one", "two", "three"):
        cached_language_model([f"send placebot {number} to zone a"], cache_dir=tmp_path)
        [newest] = set(tmp_path.glob("language-model-*.json")) - set(files)
        files.append(newest)
    assert sorted(tmp_path.iterdir()) == sorted(files[1:])
    # The one forgotten is built again when asked for.
    _, cached = cached_language_model(["send placebot one to zone a"], cache_dir=tmp_path)
    assert not cached
