"""The simulator's NLU in German, built from the shipped de-DE model and understanding data:
requests with the verb last, "zwo" and compounds are understood, everyday German falls back,
and the German development set stays apart from what the NLU is built from."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import msgspec
import pytest

from vahr.assistant.localized import load_model, strip_invocation
from vahr.assistant.understanding import load_understanding
from vahr.domain.invocation import FALLBACK_INTENT
from vahr.errors import VahrError
from vahr.skill_model.templates import expand

if TYPE_CHECKING:
    from vahr.assistant.nlu import InteractionModel

DEVSET = Path(__file__).resolve().parents[3] / "vahr" / "assistant" / "data" / "devset-de-DE.yaml"


@pytest.fixture(scope="module")
def model() -> InteractionModel:
    return load_model("de-DE")


@pytest.mark.parametrize(
    ("said", "intent", "slots"),
    [
        ("Alexa, sage Roboterflotte, schicke Placebot eins in Zone B", "NavigateIntent",
         {"robot": "placebot1", "zone": "B"}),
        ("Alexa, frag Roboterflotte, wo ist placebot zwo", "StatusIntent", {"robot": "placebot2"}),
        ("lass placebot zwo ein paket in die lieferzone d bringen", "DeliverIntent",
         {"robot": "placebot2", "zone": "D"}),
        ("placebot eins soll die wetterlieferung erledigen", "WeatherDeliveryIntent",
         {"robot": "placebot1"}),
        ("stopp placebot zwei", "EmergencyStopIntent", {"robot": "placebot2"}),
    ],
)  # fmt: skip
def test_german_requests_are_understood(
    model: InteractionModel, said: str, intent: str, slots: dict[str, str]
) -> None:
    understood = model.understand(strip_invocation(model.invocation_name, said, "de-DE"))
    assert understood.intent == intent
    assert {name: value.id for name, value in understood.slots.items()} == slots


@pytest.mark.parametrize("said", ["spiel musik von nena", "wie spät ist es in tokio"])
def test_everyday_german_falls_back(model: InteractionModel, said: str) -> None:
    assert model.understand(said).intent == FALLBACK_INTENT


def test_the_german_development_set_is_no_sample_or_training_phrase(
    model: InteractionModel,
) -> None:
    devset = msgspec.yaml.decode(DEVSET.read_bytes())
    sentences = [item["text"] for item in devset["utterances"]] + devset["out_of_domain"]
    assert len(devset["utterances"]) >= 150 and len(devset["out_of_domain"]) >= 50
    training = set(model.training[0])
    understanding = load_understanding("de-DE")
    phrases = {
        sentence
        for templates in [*understanding.built_in.values(), understanding.out_of_domain]
        for template in templates
        for sentence in expand(template)
    }
    tuning = msgspec.yaml.decode(DEVSET.with_name("tuning-de-DE.yaml").read_bytes())
    tuned_on = {item["text"] for item in tuning["utterances"]} | set(tuning["out_of_domain"])
    for sentence in sentences:
        assert sentence not in training and sentence not in phrases, sentence
        assert sentence not in tuned_on, sentence


def test_an_unknown_locale_is_refused_in_one_line() -> None:
    with pytest.raises(VahrError, match=r"^unknown locale 'fr-FR'; supported: de-DE, en-US$"):
        load_model("fr-FR")
