"""The `Link` port: publish and route MQTT messages, without saying which library does it.

Robots implement it with awscrt (`robot_agent.link.mqtt5`), the lab side with paho
(`vahr.plumbing.mqtt`); the agent, the device shadow and the room channel speak through it.
Every publish is QoS 1. Handlers run on one thread the adapter chooses (the agent's event
loop for awscrt, paho's network thread for the lab): keep them short. One link can carry
many robots (swarm mode): each adds its routes.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Protocol

if TYPE_CHECKING:
    from collections.abc import Callable


class Link(Protocol):
    def publish(self, topic: str, payload: bytes, *, retain: bool = False) -> None:
        """Publish with QoS 1 (queued while offline where the adapter can)."""

    def add_route(self, topic_filter: str, handler: Callable[[str, bytes], None]) -> None:
        """Subscribe to `topic_filter` (QoS 1) and call `handler(topic, payload)` for each match."""

    def on_connected(self, callback: Callable[[bool], None]) -> None:
        """Call `callback(session_present)` after every successful connection."""

    def on_disconnected(self, callback: Callable[[str], None]) -> None:
        """Call `callback(reason)` whenever the connection drops."""


def topic_matches(topic_filter: str, topic: str) -> bool:
    """MQTT topic matching with `+` and `#` (`$` topics are matched only by `$` filters)."""
    if topic.startswith("$") != topic_filter.startswith("$"):
        return False
    filter_levels = topic_filter.split("/")
    topic_levels = topic.split("/")
    for index, level in enumerate(filter_levels):
        if level == "#":
            return True
        if index >= len(topic_levels):
            return False
        if level != "+" and level != topic_levels[index]:
            return False
    return len(filter_levels) == len(topic_levels)
