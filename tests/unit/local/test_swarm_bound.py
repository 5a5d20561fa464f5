"""`vahr up --swarm N`'s bound: the interaction model generated for the largest swarm it
takes must be one Alexa accepts (its ROBOT slot type names every robot), so that the bound,
not the skill's deploy, is where a too-large swarm is refused."""

from __future__ import annotations

from vahr.local.robots import SWARM_MAX, generated_fleet
from vahr.skill_model.generator import MAX_MODEL_CHARS, build_interaction_model, render


def test_the_largest_swarm_has_a_model_alexa_accepts() -> None:
    model = build_interaction_model(generated_fleet(SWARM_MAX))
    assert len(render(model)) <= MAX_MODEL_CHARS
