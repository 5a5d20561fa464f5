"""Amazon Polly as the robot's voice, against moto: the request Polly gets (16 kHz PCM, the
chosen voice) and the errors a user sees. moto returns placeholder audio, so what is
asserted is the request and its translation, not the sound."""

from __future__ import annotations

from typing import TYPE_CHECKING

import boto3
import pytest
from moto import mock_aws

from vahr.speech.errors import SpeechError
from vahr.speech.tts import PollySynthesizer

if TYPE_CHECKING:
    from collections.abc import Iterator


@pytest.fixture
def polly(monkeypatch: pytest.MonkeyPatch) -> Iterator[object]:
    for name, value in {"AWS_ACCESS_KEY_ID": "testing", "AWS_SECRET_ACCESS_KEY": "testing",
                        "AWS_DEFAULT_REGION": "us-east-1"}.items():  # fmt: skip
        monkeypatch.setenv(name, value)
    with mock_aws():
        yield boto3.client("polly", region_name="us-east-1")


def test_polly_is_asked_for_16k_pcm_in_the_chosen_voice(polly: object) -> None:
    sent: list[dict[str, object]] = []
    polly.meta.events.register(  # type: ignore[attr-defined]
        "provide-client-params.polly.SynthesizeSpeech", lambda params, **_: sent.append(params)
    )
    audio = PollySynthesizer("Matthew", client=polly).synthesize("  The weather is sunny.  ")
    assert sent == [
        {"Text": "The weather is sunny.", "VoiceId": "Matthew", "OutputFormat": "pcm",
         "SampleRate": "16000", "Engine": "standard"}
    ]  # fmt: skip
    assert len(audio.pcm) % 2 == 0


def test_a_polly_error_is_a_voice_error(polly: object) -> None:
    with pytest.raises(SpeechError, match="Amazon Polly could not speak"):
        PollySynthesizer("NoSuchVoice", client=polly).synthesize("hello")


def test_empty_text_is_refused_before_any_request(polly: object) -> None:
    with pytest.raises(SpeechError, match="the text is empty"):
        PollySynthesizer(client=polly).synthesize("   ")
