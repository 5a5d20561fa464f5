"""The generated ACL mirrors the AWS IoT policy of a robot (the broker enforces it live in
tests/integration/local/test_acl_enforced.py)."""

from __future__ import annotations

from vahr.twin.acl import render_acl


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


def test_the_service_identity_may_use_every_topic_including_aws_reserved_ones() -> None:
    lines = render_acl().splitlines()
    user = lines.index("user vahr-service")
    assert lines[user + 1 : user + 3] == ["topic readwrite #", "topic readwrite $aws/#"]


def test_anonymous_access_only_exists_when_the_plaintext_listener_is_on() -> None:
    closed = render_acl().splitlines()
    opened = render_acl(open_anonymous=True).splitlines()
    first_user = closed.index("user vahr-service")
    assert not any(line.startswith("topic") for line in closed[:first_user])
    assert opened[1:3] == ["topic readwrite #", "topic readwrite $aws/#"]
