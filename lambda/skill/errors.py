"""The skill's small exception hierarchy; `skill.handlers.catch_all` maps it to speech in one
place."""

from __future__ import annotations


class SkillError(Exception):
    """Base of every error the skill raises on purpose."""


class ConfigError(SkillError):
    """A configuration variable is set to a value the skill cannot use (raised at cold start)."""


class GatewayError(SkillError):
    """AWS IoT (or the local data plane) refused or failed a publish or a shadow call."""


class MissingCredentials(GatewayError):
    """boto3 found no AWS credentials to sign a data-plane call with."""


class ShadowConflict(GatewayError):
    """A shadow update carried a version that is no longer current (HTTP 409)."""


class PeopleUnavailable(GatewayError):
    """The directory of people could not be read (the table unreachable, access denied)."""


class TrailUnavailable(GatewayError):
    """The audit trail could not take a record."""
