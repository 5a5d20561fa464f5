"""A small evaluator of AWS IoT Core policy documents, for testing what a robot may do.

It models what the robot policy uses: Allow and Deny (an explicit Deny wins, nothing
allowed means denied), actions with `*` wildcards, resources with `*` and `?` wildcards
after the connection's policy variables are substituted, and the `Bool` / `StringEquals`
condition operators. It refuses anything it does not model, so a policy growing beyond
it fails the tests instead of being judged wrongly. Resource types matter as in IoT:
iot:Subscribe is checked against `topicfilter/<filter>` (MQTT `+` and `#` are literal
characters there), iot:Publish and iot:Receive against `topic/<topic>`.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from typing import Any

_VARIABLE = re.compile(r"\$\{([^}]+)\}")


@dataclass(frozen=True)
class Connection:
    """Who is asking: the client's thing (when its certificate is attached to one)."""

    thing: str | None
    arn_prefix: str = "arn:aws:iot:us-east-1:123456789012"

    @property
    def variables(self) -> dict[str, str]:
        if self.thing is None:
            return {"iot:Connection.Thing.IsAttached": "false"}
        return {
            "iot:Connection.Thing.ThingName": self.thing,
            "iot:Connection.Thing.IsAttached": "true",
        }


def _wildcard(pattern: str) -> re.Pattern[str]:
    parts = (".*" if c == "*" else "." if c == "?" else re.escape(c) for c in pattern)
    return re.compile("^" + "".join(parts) + "$", re.DOTALL)


def _as_list(value: Any) -> list[Any]:
    return value if isinstance(value, list) else [value]


class IotPolicy:
    """Evaluate one policy document for one connection."""

    def __init__(self, document: dict[str, Any], connection: Connection) -> None:
        self.statements = _as_list(document["Statement"])
        self.connection = connection
        for statement in self.statements:
            unknown = set(statement) - {"Sid", "Effect", "Action", "Resource", "Condition"}
            if unknown:
                raise ValueError(f"statement keys not modelled: {sorted(unknown)}")

    def _substitute(self, text: str) -> str | None:
        """The resource with variables replaced, or None if one cannot be (then the
        statement does not apply, as in IoT when no thing is attached)."""
        values = self.connection.variables
        missing = [name for name in _VARIABLE.findall(text) if name not in values]
        if missing:
            return None
        return _VARIABLE.sub(lambda found: values[found[1]], text)

    def _conditions_hold(self, conditions: dict[str, Any]) -> bool:
        values = self.connection.variables
        for operator, tests in conditions.items():
            if operator not in ("Bool", "StringEquals"):
                raise ValueError(f"condition operator not modelled: {operator}")
            for key, expected in tests.items():
                actual = values.get(key)
                wanted = [str(item).lower() for item in _as_list(expected)]
                if actual is None or actual.lower() not in wanted:
                    return False
        return True

    def _matches(self, statement: dict[str, Any], action: str, resource: str) -> bool:
        if not any(_wildcard(pattern).match(action) for pattern in _as_list(statement["Action"])):
            return False
        if not self._conditions_hold(statement.get("Condition", {})):
            return False
        for pattern in _as_list(statement["Resource"]):
            substituted = self._substitute(pattern)
            if substituted is not None and _wildcard(substituted).match(resource):
                return True
        return False

    def allows(self, action: str, resource: str) -> bool:
        matching = [s for s in self.statements if self._matches(s, action, resource)]
        if any(statement["Effect"] == "Deny" for statement in matching):
            return False
        return any(statement["Effect"] == "Allow" for statement in matching)

    # The MQTT operations, with the resource type IoT checks for each.
    def _arn(self, kind: str, name: str) -> str:
        return f"{self.connection.arn_prefix}:{kind}/{name}"

    def can_connect(self, client_id: str) -> bool:
        return self.allows("iot:Connect", self._arn("client", client_id))

    def can_publish(self, topic: str, *, retain: bool = False) -> bool:
        allowed = self.allows("iot:Publish", self._arn("topic", topic))
        if retain:
            allowed = allowed and self.allows("iot:RetainPublish", self._arn("topic", topic))
        return allowed

    def can_subscribe(self, topic_filter: str) -> bool:
        return self.allows("iot:Subscribe", self._arn("topicfilter", topic_filter))

    def can_receive(self, topic: str) -> bool:
        return self.allows("iot:Receive", self._arn("topic", topic))
