"""Which skill's requests the handler serves: the check before any handler runs.

Anyone who learns the function's ARN can point a skill of their own at it, and Lambda's
permission stops them only when it carries the skill id (`EventSourceToken`). So the
handler checks every request's `applicationId` itself, and fails closed:

- a skill id is configured: only requests carrying it are served;
- none is configured and the function runs on Lambda: nothing is served, unless the
  deployment said explicitly that any skill may call it (`VAHR_ALLOW_ANY_SKILL`, set by
  `cdk deploy -c allowAnySkill=true`);
- none is configured off Lambda (the tests, a handler built in-process): requests are
  served, as there is no ARN to learn. The local stack configures a skill id of its own
  and its Alexa simulator's envelopes carry it, so the local path checks too.

A refused request gets a valid Alexa answer (the skill must always speak) that says nothing
was sent, and one log line naming the applicationId refused; nothing reaches the robots.
"""

from __future__ import annotations

from typing import Any

import msgspec

NO_SKILL_ID = "no skill id is configured"
ANOTHER_SKILL = "the request is for another skill"
NO_APPLICATION_ID = "the request carries no applicationId"


class SkillGate(msgspec.Struct, frozen=True):
    """The rule above, for one configuration."""

    skill_id: str | None
    allow_any_skill: bool = False
    on_lambda: bool = False

    def refusal(self, event: object) -> str | None:
        """None when `event` may be served, else why not (for the log line)."""
        if self.skill_id is None:
            if self.on_lambda and not self.allow_any_skill:
                return NO_SKILL_ID
            return None
        carried = application_ids(event)
        if not carried:
            return NO_APPLICATION_ID
        if any(application != self.skill_id for application in carried):
            return ANOTHER_SKILL
        return None


def application_ids(event: object) -> list[str]:
    """Every applicationId the envelope carries (its context's and its session's)."""
    found = [
        _dig(event, "context", "System", "application", "applicationId"),
        _dig(event, "session", "application", "applicationId"),
    ]
    return [
        value if isinstance(value, str) else repr(value) for value in found if value is not None
    ]


def _dig(value: Any, *keys: str) -> Any:
    for key in keys:
        if not isinstance(value, dict):
            return None
        value = value.get(key)
    return value
