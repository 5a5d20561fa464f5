"""Helpers for reading synthesized CloudFormation templates in the infra tests."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import aws_cdk as cdk

REPO_ROOT = Path(__file__).resolve().parents[2]
PARTITION, REGION, ACCOUNT = "aws", "us-east-1", "123456789012"
PSEUDO = {"AWS::Partition": PARTITION, "AWS::Region": REGION, "AWS::AccountId": ACCOUNT}


# A developer's own `ask deploy` state must not change what the tests synthesize.
NO_ASK_STATES = str(REPO_ROOT / ".ask" / "absent-in-tests.json")
# The skill whose id the tests' apps know, as after `ask deploy` (synth refuses an app
# that knows none); a test that is about the skill id overrides `skillId`.
SKILL_ID = "amzn1.ask.skill.0d5c1d3e-52b4-4a53-9f0e-6f1a2b3c4d5e"


def cdk_context(**overrides: Any) -> dict[str, Any]:
    """cdk.json's context (pytest's `cdk.App()` does not read it), bundling skipped, and
    the skill id `SKILL_ID`."""
    context: dict[str, Any] = json.loads((REPO_ROOT / "cdk.json").read_text())["context"]
    return {
        **context, "aws:cdk:bundling-stacks": [], "askStatesFile": NO_ASK_STATES,
        "skillId": SKILL_ID, **overrides,
    }  # fmt: skip


def bare_stack(outdir: Path, **context: Any) -> cdk.Stack:
    """An empty stack in its own app, for one construct under test."""
    app = cdk.App(context=cdk_context(**context), outdir=str(outdir))
    return cdk.Stack(app, "Bare")


def resolve(value: Any) -> Any:
    """Resolve the intrinsics CDK emits for ARNs, with fixed partition, region and account.

    Other resources' references become `<LogicalId>` / `<LogicalId.Attribute>`.
    """
    if isinstance(value, list):
        return [resolve(item) for item in value]
    if not isinstance(value, dict):
        return value
    if set(value) == {"Ref"}:
        return PSEUDO.get(value["Ref"], f"<{value['Ref']}>")
    if set(value) == {"Fn::GetAtt"}:
        logical_id, attribute = value["Fn::GetAtt"]
        return f"<{logical_id}.{attribute}>"
    if set(value) == {"Fn::Join"}:
        separator, parts = value["Fn::Join"]
        return separator.join(str(resolve(part)) for part in parts)
    if set(value) == {"Fn::Sub"} and isinstance(value["Fn::Sub"], str):
        text = value["Fn::Sub"]
        for name, replacement in PSEUDO.items():
            text = text.replace("${" + name + "}", replacement)
        return text
    return {key: resolve(item) for key, item in value.items()}


def resources(template: dict[str, Any], resource_type: str) -> dict[str, dict[str, Any]]:
    """Logical id -> resolved Properties, for every resource of `resource_type`."""
    return {
        logical_id: resolve(resource.get("Properties", {}))
        for logical_id, resource in template["Resources"].items()
        if resource["Type"] == resource_type
    }


def only(template: dict[str, Any], resource_type: str) -> dict[str, Any]:
    found = resources(template, resource_type)
    assert len(found) == 1, f"expected one {resource_type}, found {sorted(found)}"
    return next(iter(found.values()))


def as_list(value: Any) -> list[Any]:
    return value if isinstance(value, list) else [value]


def grants(policy_document: dict[str, Any]) -> set[tuple[str, str, str]]:
    """Every (effect, action, resource) triple a policy document states."""
    triples = set()
    for statement in policy_document["Statement"]:
        for action in as_list(statement["Action"]):
            for resource in as_list(statement["Resource"]):
                triples.add((statement["Effect"], action, resource))
    return triples


def role_grants(template: dict[str, Any], role_logical_prefix: str) -> set[tuple[str, str, str]]:
    """The grants of every inline policy attached to the role whose logical id starts so."""
    triples: set[tuple[str, str, str]] = set()
    for policy in resources(template, "AWS::IAM::Policy").values():
        if any(role.startswith(f"<{role_logical_prefix}") for role in policy["Roles"]):
            triples |= grants(policy["PolicyDocument"])
    return triples
