"""The test policy evaluator itself: it must deny by default, let Deny win, and match the
way IoT does, or the robot policy tests would prove nothing."""

from __future__ import annotations

import pytest
from iot_policy_eval import Connection, IotPolicy

PREFIX = "arn:aws:iot:us-east-1:123456789012"


def policy(*statements: dict[str, object]) -> dict[str, object]:
    return {"Version": "2012-10-17", "Statement": list(statements)}


def test_nothing_is_allowed_by_an_empty_policy() -> None:
    assert not IotPolicy(policy(), Connection("r1")).can_publish("a/b")


def test_an_explicit_deny_wins_over_an_allow() -> None:
    document = policy(
        {"Effect": "Allow", "Action": "iot:*", "Resource": f"{PREFIX}:topic/*"},
        {"Effect": "Deny", "Action": "iot:Publish", "Resource": f"{PREFIX}:topic/secret"},
    )
    robot = IotPolicy(document, Connection("r1"))
    assert robot.can_publish("open")
    assert not robot.can_publish("secret")


def test_star_spans_levels_and_mqtt_wildcards_are_literal_in_topicfilter() -> None:
    document = policy(
        {"Effect": "Allow", "Action": "iot:Subscribe", "Resource": f"{PREFIX}:topicfilter/a/*/c"},
        {"Effect": "Allow", "Action": "iot:Subscribe", "Resource": f"{PREFIX}:topicfilter/x/+"},
    )
    robot = IotPolicy(document, Connection("r1"))
    assert robot.can_subscribe("a/b/c") and robot.can_subscribe("a/+/c")
    assert robot.can_subscribe("a/b/b/c")  # `*` is not bounded by `/` in IoT policies
    assert robot.can_subscribe("x/+") and not robot.can_subscribe("x/y")
    # A subscribe grant is not a receive grant (different action and resource type)
    assert not robot.can_receive("a/b/c")


def test_policy_variables_and_the_attached_condition() -> None:
    document = policy(
        {
            "Effect": "Allow",
            "Action": "iot:Connect",
            "Resource": f"{PREFIX}:client/${{iot:Connection.Thing.ThingName}}",
            "Condition": {"Bool": {"iot:Connection.Thing.IsAttached": "true"}},
        }
    )
    assert IotPolicy(document, Connection("r1")).can_connect("r1")
    assert not IotPolicy(document, Connection("r1")).can_connect("r2")
    assert not IotPolicy(document, Connection(None)).can_connect("r1")


def test_unmodelled_conditions_are_refused_rather_than_guessed() -> None:
    document = policy(
        {
            "Effect": "Allow",
            "Action": "iot:Connect",
            "Resource": "*",
            "Condition": {"ForAnyValue:StringLike": {"iot:ConnectAttributes": ["LastWill"]}},
        }
    )
    with pytest.raises(ValueError, match="not modelled"):
        IotPolicy(document, Connection("r1")).can_connect("r1")
