"""Whole-app synthesis for the infra tests: one app's template, with cdk-nag on.

A module of its own (not the conftest) so tests import it by a name no other directory's
conftest shares: two `conftest` modules on one worker would shadow each other.
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import aws_cdk as cdk
from aws_cdk.assertions import Template
from template_tools import cdk_context

from infra.app import build_app

if TYPE_CHECKING:
    from pathlib import Path


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
