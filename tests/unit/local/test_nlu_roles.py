"""The roles tagger: slot roles learnt from the labelled samples, on the shipped en-US model.

Every locale, en-US among them, takes its slot roles from the tagger. These tests hold it to
what a person meant: the sentence's order of roles, a value kept to its own type's slots,
listed robots as the fleet, values turned down, zones without a weather that make no rule,
and the weather words read from the locale's language data.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import pytest

from vahr.assistant import roles
from vahr.assistant.nlu import InteractionModel
from vahr.assistant.understanding import LOCALES_DIR, load_understanding
from vahr.domain.invocation import FALLBACK_INTENT
from vahr.errors import VahrError

if TYPE_CHECKING:
    from pathlib import Path

    from vahr.assistant.nlu import Understanding


@pytest.fixture(scope="module")
def model() -> InteractionModel:
    return InteractionModel.load()


def ids(understood: Understanding) -> dict[str, str | None]:
    return {name: value.id for name, value in understood.slots.items()}


@pytest.mark.parametrize(
    ("utterance", "intent", "slots"),
    [
        ("send robot one and robot two to the loading zone", "NavigateIntent",
         {"robot": "all", "zone": "LOADING"}),
        ("move robot one from the loading zone to zone c", "NavigateIntent",
         {"robot": "placebot1", "zone": "C"}),
        ("have robot two deliver to zone d after robot one delivers to zone a",
         "SequentialDeliveryIntent",
         {"firstRobot": "placebot1", "firstZone": "A", "secondRobot": "placebot2",
          "secondZone": "D"}),
        ("robot one delivers to zone c then robot two", "SequentialDeliveryIntent",
         {"firstRobot": "placebot1", "firstZone": "C", "secondRobot": "placebot2"}),
        ("placebot one delivers to zone d and then the other robot delivers to zone c",
         "SequentialDeliveryIntent",
         {"firstRobot": "placebot1", "firstZone": "D", "secondRobot": "placebot2",
          "secondZone": "C"}),
        ("robot two if it's raining go to zone c and if it's sunny go to zone a",
         "WeatherDeliveryIntent", {"robot": "placebot2", "sunnyZone": "A", "rainyZone": "C"}),
        ("robot one if it's not sunny go to zone b otherwise zone d", "WeatherDeliveryIntent",
         {"robot": "placebot1", "sunnyZone": "D", "rainyZone": "B"}),
    ],
)  # fmt: skip
def test_roles_follow_the_sentence(
    model: InteractionModel, utterance: str, intent: str, slots: dict[str, str]
) -> None:
    understood = model.understand(utterance)
    assert (understood.intent, ids(understood)) == (intent, slots)


def test_a_weather_report_before_a_zone_makes_no_rule(model: InteractionModel) -> None:
    # "it's raining, go to zone c" says where to go, and why: no rule for the robot to follow
    assert model.understand("it is raining robot two go to zone c").intent != (
        "WeatherDeliveryIntent"
    )


def test_robots_offered_as_a_choice_are_asked_about(model: InteractionModel) -> None:
    robot = model.understand("send robot one or robot two to zone a").slots["robot"]
    # Both robots are offered, so the skill asks which one ("Placebot one or placebot two?")
    assert robot.spoken == "robot one and robot two"
    assert {robot.id, *(other for other, _ in robot.alternatives)} == {"placebot1", "placebot2"}


def test_a_value_never_takes_another_types_slot(model: InteractionModel) -> None:
    # Given a sequential delivery naming two robots and two zones
    words, matches = model.find_slots("robot one to zone a and robot two to zone b")
    # When the tagger labels them
    labels = model._taggers["SequentialDeliveryIntent"].labels(words, matches)
    # Then each robot takes a robot slot and each zone a zone slot
    kinds = {"ROBOT": {"firstRobot", "secondRobot"}, "ZONE": {"firstZone", "secondZone"}}
    for match, label in zip(matches, labels, strict=True):
        assert label.lstrip("+?").split("&")[0] in kinds[match.type] | {roles.NO_SLOT}


def test_each_intent_with_slots_has_a_tagger(model: InteractionModel) -> None:
    assert set(model._taggers) == {name for name, slots in model.intent_slots.items() if slots}


def test_the_tagger_is_cached_by_its_data(model: InteractionModel, tmp_path: Path) -> None:
    intent = "SequentialDeliveryIntent"
    slots, sequences = model.intent_slots[intent], model.role_training[intent]

    def load(data: list[roles.Sequence_]) -> tuple[roles.RolesTagger, bool]:
        return roles.load_or_train(intent, slots, data, tmp_path, model.role_lexicon)

    # Given an empty cache, the intent's tagger is trained and written
    first, cached = load(sequences)
    [file] = tmp_path.glob("roles-*.crfsuite")
    written = file.stat().st_mtime_ns
    assert not cached
    # Then loaded again it is read from the cache, not trained and written again
    again, cached = load(sequences)
    assert cached and file.stat().st_mtime_ns == written
    words, matches = model.find_slots("robot two to zone d after robot one to zone a")
    assert again.labels(words, matches) == first.labels(words, matches)
    # And other data is another tagger, in a file of its own
    _, cached = load(sequences[1:])
    assert not cached and len(list(tmp_path.glob("roles-*.crfsuite"))) == 2


def test_a_model_whose_taggers_are_cached_reads_no_features(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    # Given a model loaded once, its taggers learnt and cached
    first = InteractionModel.load(cache_dir=tmp_path)
    learnt = sorted(tmp_path.glob("roles-*.crfsuite"))
    assert len(learnt) == len(first._taggers)

    # When it is loaded again with the features out of reach
    def no_features(*args: object) -> list[list[str]]:
        raise AssertionError("features read for a cached tagger")

    monkeypatch.setattr(roles, "value_features", no_features)
    again = InteractionModel.load(cache_dir=tmp_path)
    monkeypatch.undo()  # (understanding reads the features of what is said)
    # Then it reads every tagger from the cache, and understands as the first did
    assert sorted(tmp_path.glob("roles-*.crfsuite")) == learnt
    said = "robot two to zone d after robot one to zone a"
    assert again.understand(said) == first.understand(said)


def test_a_tagger_is_learnt_again_when_the_weather_words_change(
    model: InteractionModel, tmp_path: Path
) -> None:
    intent = "WeatherDeliveryIntent"
    slots, values = model.intent_slots[intent], model._role_values[intent]
    english = model.role_lexicon
    _, cached = roles.load_or_learn(intent, slots, values, tmp_path, english)
    assert not cached
    assert roles.load_or_learn(intent, slots, values, tmp_path, english)[1]
    # A weather word more is another tagger (its features differ)
    more = roles.WeatherLexicon({**english.weathers, "drizzly": "rainy"}, english.negations)
    assert not roles.load_or_learn(intent, slots, values, tmp_path, more)[1]


def test_nothing_understood_is_nothing_assigned(model: InteractionModel) -> None:
    assert model.understand("play some jazz").intent == FALLBACK_INTENT


def test_the_weather_words_are_the_locales() -> None:
    # Given English's language data: "sunny" names a weather, "not" turns it round
    english = roles.WeatherLexicon.of_locale("en-US")
    words = "if it is not sunny go to zone b".split()
    assert english.weather_of(words, words.index("sunny")) == "rainy"
    # A locale with no language data gives the tagger no weather to read
    assert roles.WeatherLexicon.of_locale("xx-XX").weather_of(words, 4) is None


def test_a_switch_back_to_hand_rules_is_refused_in_one_line(tmp_path: Path) -> None:
    # Given an understanding file that still asks for the English hand rules, which are gone
    shipped = (LOCALES_DIR / "en-US" / "understanding.yaml").read_text()
    (tmp_path / "en-US").mkdir()
    (tmp_path / "en-US" / "understanding.yaml").write_text(shipped + "english_role_rules: true\n")
    # When it is loaded, Then one line names the key
    with pytest.raises(VahrError, match=r"understanding.yaml: .*english_role_rules"):
        load_understanding("en-US", directory=tmp_path)
    # and the shipped file is en-US's, with no such key
    assert load_understanding().locale == "en-US"


@pytest.mark.parametrize(
    ("utterance", "slots"),
    [
        # A robot's turn said after its name ("goes second"): the tagger does not always
        # give the turn or the shared zone, and then the skill asks; it never sends a robot
        # in the other order or to another zone.
        ("placebot two goes second placebot one goes first both deliver to zone d",
         {"firstRobot": "placebot1", "firstZone": "D", "secondRobot": "placebot2",
          "secondZone": "D"}),
        ("placebot two second and placebot one first deliver to zone d",
         {"firstRobot": "placebot1", "firstZone": "D", "secondRobot": "placebot2",
          "secondZone": "D"}),
    ],
)  # fmt: skip
def test_turns_after_the_names_are_right_or_asked_about(
    model: InteractionModel, utterance: str, slots: dict[str, str]
) -> None:
    understood = model.understand(utterance)
    assert understood.intent == "SequentialDeliveryIntent"
    # Each slot is what was said, or empty or unresolved (so the skill asks for it)
    assert all(ids(understood).get(name) in (None, value) for name, value in slots.items())
    # and the first robot is always the one said to go first
    assert ids(understood).get("firstRobot") in (None, "placebot1")
