"""Push-to-talk: the clip's checks, the vocabulary from the interaction model, how made-up
words are pronounced, and what the page is answered for speech, silence and nonsense."""

from __future__ import annotations

import io
import subprocess
import threading
import wave
from collections import Counter
from typing import TYPE_CHECKING, Any

import pytest

from vahr.domain.text import spell_numbers
from vahr.speech.errors import SpeechError
from vahr.speech.pronounce import arpabet, compound_phones
from vahr.speech.stt import NOTHING_HEARD, Hypothesis, Recognition
from vahr.station.errors import RequestError
from vahr.station.vocabulary import load_model, sentences
from vahr.station.voice import SORRY, PushToTalk, read_clip

if TYPE_CHECKING:
    from collections.abc import Iterator
    from pathlib import Path

    from vahr.domain import Fleet
    from vahr.speech.audio import Audio


def wav(channels: int = 1, width: int = 2, rate: int = 16_000, seconds: float = 1.0) -> bytes:
    buffer = io.BytesIO()
    with wave.open(buffer, "wb") as out:
        out.setnchannels(channels)
        out.setsampwidth(width)
        out.setframerate(rate)
        out.writeframes(bytes(int(seconds * rate) * channels * width))
    return buffer.getvalue()


@pytest.fixture(scope="module", autouse=True)
def shipped_model_built_once() -> Iterator[None]:
    """The push-to-talks made here each build the NLU that ships (0.9 s of CPU) on first
    use; they share one, as the push-to-talk of one station does."""
    from vahr.assistant import InteractionModel

    shipped = InteractionModel.load()
    load = InteractionModel.load

    def shipped_or_loaded(path: Path | None = None, **options: Any) -> InteractionModel:
        return shipped if path is None and not options else load(path, **options)

    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(InteractionModel, "load", shipped_or_loaded)
        yield


class Heard:
    """A recognizer that hears what it is told to."""

    def __init__(self, recognition: Recognition) -> None:
        self.recognition = recognition

    def recognize(self, audio: Audio) -> Recognition:
        return self.recognition


class Assistant:
    def __init__(self, intent: str) -> None:
        self.intent = intent
        self.asked: list[tuple[str, str, dict[str, Any] | None]] = []

    def ask(
        self,
        utterance: str,
        *,
        origin: str = "say",
        heard: dict[str, Any] | None = None,
        user: str | None = None,
    ) -> dict[str, Any]:
        self.asked.append((utterance, origin, heard))
        return {
            "speech": "Placebot two is on its way to zone C.",
            "intent": self.intent,
            "commands": ["c1"],
        }


def test_a_16_khz_mono_clip_is_read() -> None:
    assert read_clip(wav(seconds=2.0)).seconds == 2.0


@pytest.mark.parametrize(
    "clip",
    [
        wav(rate=22_050, seconds=2.0),  # espeak-ng's own rate
        wav(channels=2, rate=44_100, seconds=2.0),  # a phone's recording
        wav(width=1, rate=8_000, seconds=2.0),  # 8-bit
    ],
)
def test_any_pcm_wav_a_person_has_is_read_at_16_khz_mono(clip: bytes) -> None:
    audio = read_clip(clip)
    assert audio.seconds == pytest.approx(2.0, abs=0.01)


def test_espeak_ngs_own_wav_is_read(tmp_path: Path) -> None:
    # `espeak-ng -w FILE` writes 22,050 Hz mono, which a user may well post as it is
    out = tmp_path / "stop.wav"
    subprocess.run(["espeak-ng", "-w", str(out), "stop all the robots"], check=True)
    with wave.open(str(out), "rb") as native:
        assert native.getframerate() == 22_050
    assert read_clip(out.read_bytes()).seconds > 0.5


@pytest.mark.parametrize(
    ("data", "status", "words"),
    [
        (b"ID3 an mp3 file", 415, "not a WAV file"),
        (wav(seconds=21.0), 413, "at most 20 s"),
        (wav(rate=44_100, seconds=21.0), 413, "at most 20 s"),
        (b"RIFF\x00\x00\x00\x00WAVEjunk", 400, "not readable as audio"),
    ],
)
def test_any_other_clip_is_refused_with_one_line(data: bytes, status: int, words: str) -> None:
    with pytest.raises(RequestError) as refused:
        read_clip(data)
    assert refused.value.status == status and words in refused.value.message


def test_speech_heard_goes_to_the_assistant_with_what_was_heard() -> None:
    assistant = Assistant("NavigateIntent")
    heard = Recognition("send placebot two to zone c", 0.81, True)
    result = PushToTalk(assistant, lambda: Heard(heard)).handle(wav())
    assert result["understood"] is True
    assert result["speech"] == "Placebot two is on its way to zone C."
    ((utterance, origin, sent),) = assistant.asked
    assert (utterance, origin) == ("send placebot two to zone c", "station-voice")
    assert sent is not None
    weighed = sent.pop("weighed")
    assert sent == {
        "transcript": "send placebot two to zone c",
        "confidence": 0.81,
        "accepted": True,
        "seconds": 1.0,
    }
    # One reading, understood by the NLU: the robot and the zone are sure.
    assert weighed["intent"] == "NavigateIntent"
    assert weighed["slots"] == {"robot": 1.0, "zone": 1.0}


@pytest.mark.parametrize(
    ("recognition", "intent", "asked"),
    [
        (NOTHING_HEARD, "NavigateIntent", False),  # silence
        (Recognition("what tell every d", 0.02, False), "NavigateIntent", False),  # unsure
        # understood by the NLU as nothing the skill does: not even sent
        (Recognition("play some music please", 0.6, True), "NavigateIntent", False),
    ],
)
def test_silence_and_what_is_not_understood_get_sorry(
    recognition: Recognition, intent: str, asked: bool
) -> None:
    assistant = Assistant(intent)
    result = PushToTalk(assistant, lambda: Heard(recognition)).handle(wav())
    assert (result["understood"], result["speech"]) == (False, SORRY)
    assert bool(assistant.asked) == asked


def test_the_vocabulary_follows_the_interaction_model(fleet: Fleet) -> None:
    said = sentences(load_model())
    text = "\n".join(said)
    # Every name of every robot and zone in fleet.yaml is in it, numbers spelled out
    for name in [
        *(n for r in fleet.robots for n in r.spoken),
        *(n for z in fleet.zones for n in z.spoken),
    ]:
        assert spell_numbers(name) in text, name
    assert "placebot 2" not in text
    # with the ways of addressing the skill and Alexa's built-in phrases
    assert any(s.startswith("ask robot fleet to send ") for s in said)
    assert "open robot fleet" in said and "help" in said


def test_numbers_are_spelled_as_people_say_them() -> None:
    assert spell_numbers("placebot 2 to zone 42") == "placebot two to zone forty two"
    assert spell_numbers("robot 100") == "robot 100"


def test_made_up_words_are_pronounced_two_ways() -> None:
    dictionary = {"place": "P L EY S", "bot": "B AA T"}
    assert compound_phones("placebot", dictionary.get) == "P L EY S B AA T"
    assert compound_phones("zorblax", dictionary.get) is None
    # espeak-ng's own reading, its mnemonics mapped to ARPAbet
    assert arpabet("pl@s'Eb0t") == "P L AH S EH B AA T"
    assert arpabet("tS'A@li") == "CH AA R L IY"


@pytest.mark.parametrize(
    ("readings", "question"),
    [
        # The N best split between zone d and zone b
        (
            ["send placebot two to zone d", "send placebot two to zone b"],
            "Did you say zone d or zone b? Please say it again.",
        ),
        # Only the best reading names a zone; the others lack one
        (
            ["send placebot one to zone a", "send placebot one to zone hey",
             "send placebot one to the zone"],
            "I'm not sure which zone you said. Please say it again.",
        ),
    ],
    ids=["rival zones", "zone heard by too few"],
)  # fmt: skip
def test_a_remote_assistant_is_not_sent_a_zone_the_hearing_is_unsure_of(
    readings: list[str], question: str
) -> None:
    # The assistant (over HTTP) would re-read the best transcript's words and act on its
    # zone, so the station asks back itself.
    assistant = Assistant("NavigateIntent")
    hypotheses = tuple(Hypothesis(text, -60.0 * rank) for rank, text in enumerate(readings))
    heard = Recognition(readings[0], 0.6, True, hypotheses=hypotheses)
    result = PushToTalk(assistant, lambda: Heard(heard)).handle(wav())
    assert assistant.asked == []
    assert result["speech"] == question
    assert result["heard"]["weighed"]["slots"]["zone"] < 0.9


def test_a_thousand_robots_share_out_their_names_and_each_is_heard() -> None:
    from vahr.local.robots import generated_fleet
    from vahr.skill_model.generator import build_interaction_model

    document = build_interaction_model(generated_fleet(1000))
    found = sentences(document)
    # Not every sample written with each of the ~1,000 names (1.2 million sentences)...
    assert len(found) < 250_000
    # ...yet every robot's name is among them, in more than one context
    language = document["interactionModel"]["languageModel"]
    [robots] = [t for t in language["types"] if t["name"] == "ROBOT"]
    names = {spell_numbers(value["name"]["value"].lower()) for value in robots["values"]}
    # The lengths of the names beginning with each word: only those phrases are looked up.
    lengths: dict[str, set[int]] = {}
    for name in names:
        lengths.setdefault(name.split()[0], set()).add(len(name.split()))
    said: Counter[str] = Counter()
    for sentence in found:
        words = sentence.split()
        for start, word in enumerate(words):
            for length in lengths.get(word, ()):
                phrase = " ".join(words[start : start + length])
                if phrase in names:
                    said[phrase] += 1
    assert all(said[name] >= 2 for name in names), sorted(n for n in names if said[n] < 2)


class SecondEar:
    """A second recognizer that hears what it is told to, or fails."""

    def __init__(self, text: str | Exception) -> None:
        self.text = text

    def transcribe(self, audio: Audio) -> str:
        if isinstance(self.text, Exception):
            raise self.text
        return self.text


def split_b_and_d() -> Recognition:
    """The N best split between zone B and zone D: weighed alone, it is asked about."""
    readings = ["send placebot one to zone b", "send placebot one to zone d"]
    hypotheses = tuple(Hypothesis(text, -60.0 * rank) for rank, text in enumerate(readings))
    return Recognition(readings[0], 0.6, True, hypotheses=hypotheses)


def test_a_second_ear_that_agrees_with_the_best_transcript_is_acted_on() -> None:
    assistant = Assistant("NavigateIntent")
    ears = PushToTalk(
        assistant,
        lambda: Heard(split_b_and_d()),
        lambda: SecondEar("Send placebot one to zone B."),
    )
    result = ears.handle(wav())
    ((utterance, _, sent),) = assistant.asked
    assert utterance == "send placebot one to zone b"
    assert sent is not None and sent["second"] == "Send placebot one to zone B."
    assert sent["weighed"]["agreed"] is True
    assert result["understood"] is True


@pytest.mark.parametrize(
    "second",
    [
        "Send placebot one to zone D.",  # it hears the other zone
        RuntimeError("the model crashed"),  # it fails on this clip
    ],
)
def test_without_agreement_the_n_best_decide(second: str | Exception) -> None:
    assistant = Assistant("NavigateIntent")
    ears = PushToTalk(assistant, lambda: Heard(split_b_and_d()), lambda: SecondEar(second))
    result = ears.handle(wav())
    # The zone is asked about, as the first recognizer's N best alone would have it
    assert assistant.asked == []
    assert result["speech"] == "Did you say zone b or zone d? Please say it again."
    assert result["heard"]["weighed"]["agreed"] is False


@pytest.mark.parametrize(
    ("second", "asked"),
    [
        # It hears the same command with zone B: the two ears dispute the zone
        ("Send placebot one to zone B.", "Did you say zone d or zone b? Please say it again."),
        # It hears something else altogether: the N best decide alone
        ("What's the weather like?", None),
    ],
    ids=["another zone", "another intent"],
)
def test_a_zone_the_second_ear_heard_otherwise_is_asked_about(
    second: str, asked: str | None
) -> None:
    # The N best alone are sure of zone D and would send the robot there
    assistant = Assistant("NavigateIntent")
    sure_of_d = Recognition("send placebot one to zone d", 0.9, True,
                            hypotheses=(Hypothesis("send placebot one to zone d", 0.0),))  # fmt: skip
    result = PushToTalk(assistant, lambda: Heard(sure_of_d), lambda: SecondEar(second)).handle(
        wav()
    )
    if asked is None:
        ((utterance, _, _),) = assistant.asked
        assert utterance == "send placebot one to zone d" and result["understood"] is True
    else:
        assert assistant.asked == [] and result["speech"] == asked


def test_a_stop_only_the_second_ear_heard_clearly_is_acted_on() -> None:
    # Given pocketsphinx heard "all the robots now" (nothing the skill does), and Whisper
    # heard the whole request word for word
    assistant = Assistant("EmergencyStopIntent")
    first = Recognition("all the robots now", 0.7, True,
                        hypotheses=(Hypothesis("all the robots now", 0.0),))  # fmt: skip
    ears = PushToTalk(
        assistant, lambda: Heard(first), lambda: SecondEar("Stop all the robots right now.")
    )
    result = ears.handle(wav())
    # Then the stop goes to the assistant, in the words the second ear heard
    ((utterance, _, sent),) = assistant.asked
    assert utterance == "Stop all the robots right now."
    assert sent is not None and sent["weighed"]["intent"] == "EmergencyStopIntent"
    assert result["understood"] is True


def test_a_stop_the_second_ear_heard_wins_over_another_request() -> None:
    # The first ear is sure of a navigation; the second clearly heard a stop: stopping is
    # always safe, so the stop is what is done
    assistant = Assistant("EmergencyStopIntent")
    sure = Recognition("send placebot one to zone d", 0.9, True,
                       hypotheses=(Hypothesis("send placebot one to zone d", 0.0),))  # fmt: skip
    ears = PushToTalk(assistant, lambda: Heard(sure), lambda: SecondEar("Stop placebot one."))
    ears.handle(wav())
    ((utterance, _, _),) = assistant.asked
    assert utterance == "Stop placebot one."


def test_talk_of_other_things_heard_by_both_ears_sends_nothing() -> None:
    assistant = Assistant("AMAZON.FallbackIntent")
    other = Recognition("what a lovely day", 0.7, True,
                        hypotheses=(Hypothesis("what a lovely day", 0.0),))  # fmt: skip
    ears = PushToTalk(assistant, lambda: Heard(other), lambda: SecondEar("What a lovely day."))
    result = ears.handle(wav())
    assert assistant.asked == [] and result["understood"] is False


def test_a_second_ear_that_cannot_be_made_leaves_the_first_alone(
    caplog: pytest.LogCaptureFixture,
) -> None:
    def missing() -> SecondEar:
        raise SpeechError("Whisper's weights are not installed: run `make setup`")

    assistant = Assistant("NavigateIntent")
    heard = Recognition("send placebot two to zone c", 0.81, True)
    result = PushToTalk(assistant, lambda: Heard(heard), missing).handle(wav())
    assert result["understood"] is True and "second" not in result["heard"]
    assert "pocketsphinx alone: Whisper's weights are not installed" in caplog.text


def test_both_ears_are_made_once_in_the_background_when_asked() -> None:
    made: list[Heard | SecondEar] = []
    ready = threading.Event()
    heard = Recognition("send placebot two to zone c", 0.81, True)

    def make_first() -> Heard:
        made.append(Heard(heard))
        return Heard(heard)

    def make_second() -> SecondEar:
        made.append(SecondEar("Send placebot two to zone C."))
        ready.set()
        return SecondEar("Send placebot two to zone C.")

    ears = PushToTalk(Assistant("NavigateIntent"), make_first, make_second)
    assert made == []  # nothing built until someone may talk (a page opens)
    assert ears.warm_up() is not None
    assert ears.warm_up() is None
    assert ready.wait(5)
    result = ears.handle(wav())
    assert [type(ear) for ear in made] == [Heard, SecondEar]
    assert result["heard"]["second"] == "Send placebot two to zone C."
