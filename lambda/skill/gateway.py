"""The RobotGateway port: the three data-plane calls the skill makes to reach the robots.

`skill.iot_data.IotDataGateway` implements it with boto3's iot-data client (AWS IoT Core,
moto, or the local stack's data-plane API); nothing else in the skill touches boto3.
"""

from __future__ import annotations

from typing import Protocol


class RobotGateway(Protocol):
    """Publish commands and read or write classic device shadows.

    Every method raises `skill.errors.GatewayError` (or its subclass `ShadowConflict`)
    on failure and nothing else.
    """

    def publish(self, topic: str, payload: bytes) -> None:
        """Publish one message with QoS 1."""

    def get_shadow(self, thing: str) -> bytes | None:
        """The classic shadow document of `thing`, or None when it has none yet."""

    def update_shadow(self, thing: str, payload: bytes) -> bytes:
        """Apply a shadow update document; return the service's response document."""
