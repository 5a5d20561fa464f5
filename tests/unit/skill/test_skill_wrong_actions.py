"""Wrong actions by what reaches the robots: every sentence of the two development sets,
understood as typed text and handed to the real skill under moto (`SkillEffects`), sends
the commands its label means or asks; the figures are those `bench/wrong_actions.py`
measured (docs/benchmarks.md), kept as ceilings. Issue 31's target for text: at most 0.5%
of requests moving a robot where nobody asked."""

from __future__ import annotations

from collections import Counter

import pytest

from tests.support.skill_effects import SkillEffects
from vahr.assistant.evaluation import DEVELOPMENT_SET, LabelledSet, LabelledUtterance
from vahr.assistant.nlu import InteractionModel, SlotValue, Understanding
from vahr.assistant.simulator import strip_invocation
from vahr.domain.invocation import FALLBACK_INTENT
from vahr.errors import VahrError

SETS = (DEVELOPMENT_SET, DEVELOPMENT_SET.with_name("roles-devset-en-US.yaml"))


@pytest.fixture(scope="module")
def model() -> InteractionModel:
    return InteractionModel.load()


def test_the_development_sets_move_no_robot_where_nobody_asked_but_one(
    model: InteractionModel,
) -> None:
    requests: Counter[str] = Counter()
    out_of_domain: Counter[str] = Counter()
    wrong = []
    with SkillEffects(model) as effects:
        for item in (item for file in SETS for item in LabelledSet.load(file).items()):
            heard = model.understand(strip_invocation(model.invocation_name, item.text))
            verdict = effects.verdict(item, heard)
            (requests if item.intent != FALLBACK_INTENT else out_of_domain)[verdict] += 1
            if verdict in ("moved wrongly", "stopped wrongly"):
                wrong.append((item.text, effects.of(heard)))
    # Measured: 1 of 321 requests moved robots wrongly (0.3%), a sequential delivery sent
    # in the wrong order; nothing else sent anything the label does not.
    assert requests["moved wrongly"] + requests["stopped wrongly"] <= 1, wrong
    assert requests["moved wrongly"] / sum(requests.values()) <= 0.005, wrong
    assert out_of_domain["moved wrongly"] + out_of_domain["stopped wrongly"] == 0, wrong
    assert requests["as labelled"] >= 285, requests


def test_a_misheard_zone_is_a_wrong_move_and_an_unsure_robot_sends_nothing(
    model: InteractionModel,
) -> None:
    item = LabelledUtterance("send placebot one to zone b", "NavigateIntent",
                             {"robot": "placebot1", "zone": "B"})  # fmt: skip
    robot = model.slot_value("NavigateIntent", "robot", "placebot1")
    zone_d = model.slot_value("NavigateIntent", "zone", "D")
    unsure = SlotValue("robot", "ROBOT", "placebot", alternatives=(("placebot1", "placebot one"),
                       ("placebot2", "placebot two")))  # fmt: skip
    said = Understanding("NavigateIntent", {"robot": robot, "zone": zone_d}, ("robot", "zone"))
    asked = Understanding("NavigateIntent", {"robot": unsure, "zone": zone_d}, ("robot", "zone"))
    with SkillEffects(model) as effects:
        assert effects.of(said) == (("vahr/robots/placebot1/cmd", "navigate", '{"zone": "D"}'),)
        assert effects.verdict(item, said) == "moved wrongly"
        assert effects.verdict(item, asked) == "less or nothing sent"
        assert (
            effects.verdict(LabelledUtterance("what's up", FALLBACK_INTENT), said)
            == "moved wrongly"
        )
        stop_all = Understanding("EmergencyStopIntent", {}, ("robot",))
        stop_one = LabelledUtterance("stop placebot one", "EmergencyStopIntent",
                                     {"robot": "placebot1"})  # fmt: skip
        assert effects.verdict(stop_one, stop_all) == "stopped wrongly"


def test_a_labelled_value_is_said_by_its_canonical_name(model: InteractionModel) -> None:
    value = model.slot_value("SequentialDeliveryIntent", "secondZone", "LOADING")
    assert (value.id, value.canonical, value.type) == ("LOADING", "loading zone", "ZONE")
    with pytest.raises(VahrError, match="no slot zone with a value 'E'"):
        model.slot_value("NavigateIntent", "zone", "E")
