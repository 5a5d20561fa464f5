"""Who may do what on AWS: the users table and the audit table, and exactly what the skill
may do with them (read a person; append to the trail), checked on the template and, for
the trail, on the policy's own words (no update, no delete, no read but the head)."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import pytest
from aws_cdk.assertions import Template
from template_tools import bare_stack, resources, role_grants

from infra.config import InfraConfig
from infra.constructs.people_tables import PeopleTables
from infra.constructs.skill_function import SkillFunction

if TYPE_CHECKING:
    from vahr.domain import Fleet


def synth(tmp_path_factory: pytest.TempPathFactory, fleet: Fleet, *, people: bool) -> Any:
    stack = bare_stack(tmp_path_factory.mktemp("people"))
    skill = SkillFunction(
        stack,
        "Skill",
        config=InfraConfig(allow_any_skill=True),
        fleet=fleet,
        data_endpoint="a1-ats.iot.us-east-1.amazonaws.com",
    )
    tables = PeopleTables(stack, "People", people=people, audit_deletion_protection=True)
    tables.admit_trail_writer(skill.role)
    tables.admit_reader_of_people(skill.role)
    return Template.from_stack(stack).to_json()


@pytest.fixture(scope="module")
def template(tmp_path_factory: pytest.TempPathFactory, fleet: Fleet) -> Any:
    return synth(tmp_path_factory, fleet, people=True)


def tables(template: Any) -> dict[str, dict[str, Any]]:
    return {
        "users" if "Users" in logical_id else "audit": table
        for logical_id, table in resources(template, "AWS::DynamoDB::Table").items()
    }


def test_the_audit_table_keeps_its_past_and_survives_a_destroy(template: Any) -> None:
    audit = tables(template)["audit"]
    assert audit["KeySchema"] == [
        {"AttributeName": "trail", "KeyType": "HASH"},
        {"AttributeName": "seq", "KeyType": "RANGE"},
    ]
    assert audit["PointInTimeRecoverySpecification"] == {"PointInTimeRecoveryEnabled": True}
    assert audit["DeletionProtectionEnabled"] is True
    assert audit["SSESpecification"] == {"SSEEnabled": True}
    retained = [
        resource
        for resource in template["Resources"].values()
        if resource["Type"] == "AWS::DynamoDB::Table" and "trail" in str(resource)
    ]
    assert [r["DeletionPolicy"] for r in retained] == ["Retain"]


def test_the_users_table_is_keyed_by_the_alexa_id(template: Any) -> None:
    users = tables(template)["users"]
    assert users["KeySchema"] == [{"AttributeName": "id", "KeyType": "HASH"}]
    assert users["PointInTimeRecoverySpecification"] == {"PointInTimeRecoveryEnabled": True}


def test_the_skill_reads_people_and_appends_to_the_trail_and_nothing_more(
    template: Any,
) -> None:
    ids = {
        "users" if "Users" in logical_id else "audit": logical_id
        for logical_id in resources(template, "AWS::DynamoDB::Table")
    }
    users, audit = f"<{ids['users']}.Arn>", f"<{ids['audit']}.Arn>"
    dynamodb = {grant for grant in role_grants(template, "SkillRole") if "dynamodb" in grant[1]}
    assert dynamodb == {
        ("Allow", "dynamodb:GetItem", users),
        ("Allow", "dynamodb:PutItem", audit),
        ("Allow", "dynamodb:GetItem", audit),
    }
    statements = [
        statement
        for policy in resources(template, "AWS::IAM::Policy").values()
        for statement in policy["PolicyDocument"]["Statement"]
    ]
    head = next(s for s in statements if s.get("Sid") == "ReadTheTrailsHead")
    assert head["Condition"] == {"ForAllValues:StringEquals": {"dynamodb:LeadingKeys": ["head"]}}
    every_action = {grant[1] for grant in role_grants(template, "SkillRole")}
    for forbidden in ("dynamodb:UpdateItem", "dynamodb:DeleteItem", "dynamodb:Scan",
                      "dynamodb:Query", "dynamodb:BatchWriteItem", "dynamodb:*"):  # fmt: skip
        assert forbidden not in every_action


def test_without_people_there_is_no_users_table_and_no_right_to_one(
    tmp_path_factory: pytest.TempPathFactory, fleet: Fleet
) -> None:
    template = synth(tmp_path_factory, fleet, people=False)
    assert set(tables(template)) == {"audit"}
    assert ("Allow", "dynamodb:PutItem") in {g[:2] for g in role_grants(template, "SkillRole")}
