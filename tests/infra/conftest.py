"""Fixtures for the infra tests: whole-app templates synthesized once per session."""

from __future__ import annotations

import json
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import aws_cdk as cdk
import pytest
from aws_cdk.assertions import Template
from template_tools import SKILL_ID, cdk_context

from infra.app import build_app

if TYPE_CHECKING:
    from pathlib import Path

__all__ = ["SKILL_ID", "Synthesized", "synth_app"]


@dataclass(frozen=True)
class Synthesized:
    """A whole app's template, as a document and as a file (for cfn-lint)."""

    template: dict[str, Any]
    file: Path


def synth_app(outdir: Path, **context: Any) -> Synthesized:
    # cdk-nag runs on the app: from_stack raises on any unacknowledged finding.
    app = cdk.App(context=cdk_context(**context), outdir=str(outdir / "cdk.out"))
    stack = build_app(app)
    template = Template.from_stack(stack).to_json()
    file = outdir / f"{stack.stack_name}.template.json"
    file.write_text(json.dumps(template, indent=1))
    return Synthesized(template, file)


@pytest.fixture(scope="session")
def lean_app(tmp_path_factory: pytest.TempPathFactory) -> Synthesized:
    """The default deployment for a skill whose id is known: no optional parts."""
    return synth_app(tmp_path_factory.mktemp("lean"))


@pytest.fixture(scope="session")
def full_app(tmp_path_factory: pytest.TempPathFactory) -> Synthesized:
    """Every optional part: the Alexa skill and the Lex bot, with a known skill id."""
    return synth_app(tmp_path_factory.mktemp("full"), skill="true", lex="true", skillId=SKILL_ID)
