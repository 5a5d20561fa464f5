"""The generated ACL mirrors the AWS IoT policy of a robot (the broker enforces it live in
tests/integration/local/test_acl_enforced.py)."""

from __future__ import annotations

from vahr.protocol.identities import RESERVED_PREFIX
from vahr.twin.acl import render_acl
from vahr.twin.identities import SERVICES


def test_robots_get_only_their_own_topics_by_certificate_name() -> None:
    lines = render_acl().splitlines()
    assert "pattern read vahr/robots/%u/cmd" in lines
    assert "pattern read vahr/fleet/cmd" in lines
    assert "pattern read vahr/fleet/zones" in lines
    assert "pattern write vahr/robots/%u/events" in lines
    assert "pattern write vahr/robots/%u/presence" in lines
    assert "pattern read vahr/robots/+/events" in lines
    assert "pattern write $aws/things/%u/shadow/update" in lines
    assert "pattern read $aws/things/%u/shadow/update/delta" in lines
    # A robot cannot forge the shadow service's answers, not even on its own shadow.
    assert not [
        line for line in lines if "shadow" in line and "accepted" in line and "write" in line
    ]
    assert "pattern write vahr/room/%u/robot" in lines
    assert "pattern read vahr/room/%u/assistant" in lines
    # No robot line grants writing to any command topic.
    assert not [
        line for line in lines if line.startswith("pattern") and "cmd" in line and "write" in line
    ]


def test_each_service_identity_may_use_every_topic_including_aws_reserved_ones() -> None:
    lines = render_acl().splitlines()
    for service in SERVICES:
        user = lines.index(f"user {service}")
        assert lines[user + 1 : user + 3] == ["topic readwrite #", "topic readwrite $aws/#"]
    # Every service is named in full: a robot's name is never one of them
    assert {line.split()[1] for line in lines if line.startswith("user ")} == set(SERVICES)
    assert all(service.startswith(RESERVED_PREFIX) for service in SERVICES)


def test_no_anonymous_client_gets_anything() -> None:
    # Lines before the first `user` would apply to anonymous clients.
    lines = render_acl().splitlines()
    first_user = next(i for i, line in enumerate(lines) if line.startswith("user "))
    assert not any(line.startswith(("topic", "pattern")) for line in lines[:first_user])
