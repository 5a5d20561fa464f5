"""Fixtures for the infra tests: whole-app templates synthesized once per session."""

from __future__ import annotations

import pytest
from synthesis import Synthesized, synth_app
from template_tools import SKILL_ID


@pytest.fixture(scope="session")
def lean_app(tmp_path_factory: pytest.TempPathFactory) -> Synthesized:
    """The default deployment for a skill whose id is known: no optional parts."""
    return synth_app(tmp_path_factory.mktemp("lean"))


@pytest.fixture(scope="session")
def full_app(tmp_path_factory: pytest.TempPathFactory) -> Synthesized:
    """Every optional part: the Alexa skill, the Lex bot and people's roles, with a known
    skill id."""
    return synth_app(
        tmp_path_factory.mktemp("full"), skill="true", lex="true", people="true", skillId=SKILL_ID
    )
