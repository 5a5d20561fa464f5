"""docs/deploy.md and ask-resources.json stay true to the code they describe."""

from __future__ import annotations

import json
from dataclasses import replace

import pytest
from template_tools import REPO_ROOT

from infra.cost_estimate import LabUsage, Prices, estimate, fleet_markdown, markdown

DEPLOY_DOC = REPO_ROOT / "docs" / "deploy.md"


@pytest.mark.parametrize(("lex", "skill"), [(False, False), (True, True)])
def test_the_cost_tables_in_the_deploy_guide_are_the_estimates_output(
    lex: bool, skill: bool
) -> None:
    table = markdown(estimate(LabUsage(), Prices(), lex=lex, skill=skill))
    assert table in DEPLOY_DOC.read_text(), (
        "run `python -m infra.cost_estimate` and update docs/deploy.md"
    )


def test_the_fleet_dispatch_table_in_the_deploy_guide_is_the_models_output() -> None:
    assert fleet_markdown(Prices()) in DEPLOY_DOC.read_text(), (
        "run `python -m infra.cost_estimate --fleet` and update docs/deploy.md"
    )


def test_the_estimate_counts_what_a_delivery_and_a_voice_request_cost() -> None:
    # Given one lab day with one voice session of one delivery, nothing else
    usage = replace(
        LabUsage(), lab_days=1, voice_sessions=1, keyboard_sessions=0, deliveries_per_session=1,
        skill_requests_per_voice_session=1, robots=1, session_messages_per_robot_day=0,
    )  # fmt: skip
    lines = {line.item: line for line in estimate(usage, Prices(), lex=True, skill=False)}
    # Then: the command (1 in + 2 subscribers x 2) + 10 events x (1 + 2 x 2) + 9 updates in
    assert lines["IoT messages"].quantity == 5 + 10 * 5 + 9
    # And: 9 updates + 4 reads x 2 units + 2 presence changes + 1 experiment plan
    assert lines["Device Shadow operations"].quantity == 9 + 8 + 2 + 1
    assert lines["Lambda requests"].quantity == 1
    assert lines["Lex text requests"].quantity == 1.25
    assert lines["IoT connectivity"].quantity == 8 * 60 + 15
    assert lines["IoT messages"].cost == pytest.approx(64 / 1e6)


def test_ask_deploy_deploys_the_generated_skill_package() -> None:
    resources = json.loads((REPO_ROOT / "ask-resources.json").read_text())
    assert resources["askcliResourcesVersion"] == "2020-03-31"
    default = resources["profiles"]["default"]
    package = REPO_ROOT / default["skillMetadata"]["src"]
    assert (package / "skill.json").is_file()
    assert (package / "interactionModels" / "custom" / "en-US.json").is_file()
    # The function belongs to the CDK stack (IoT rights, endpoint); ASK deploys no code.
    assert "code" not in default and "skillInfrastructure" not in default
