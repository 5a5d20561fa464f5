"""The session's wire: records every command and robot event, and sends the console's commands.

It is the lab's one MQTT client (`vahr.plumbing.mqtt`) subscribed to every robot's events, to
every command topic (robot and fleet) and to what the participant does on the operator
station (`topics.EXPERIMENT_INPUT`), handing each live message to a callback. The
session is persistent (a client id fixed per experiment session, and a session expiry), so
while the recorder is down after a crash the broker queues the QoS 1 messages it misses and
delivers them when the session resumes. The keyboard-and-mouse method's console publishes
its commands here too (QoS 1, source "console"), exactly as the skill would.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from vahr.errors import VahrError
from vahr.plumbing.mqtt import MqttClient, MqttEndpoint
from vahr.protocol import topics
from vahr.protocol.broker import parse_broker_url

if TYPE_CHECKING:
    from collections.abc import Callable

    from vahr.protocol.broker import ClientCredentials

WIRE_TOPICS = (topics.ALL_EVENTS, topics.ALL_ROBOT_CMDS, topics.FLEET_CMD, topics.EXPERIMENT_INPUT)
# Long enough to outlive any crash of a session's recorder.
SESSION_EXPIRY_S = 7 * 24 * 3600


class Bus:
    """One MQTT connection: subscribed to the wire topics, able to publish commands."""

    def __init__(
        self,
        url: str,
        on_message: Callable[[str, bytes], None],
        client_id: str,
        tls: ClientCredentials | None = None,
        will: tuple[str, bytes] | None = None,
    ) -> None:
        address = parse_broker_url(url)
        if address.tls and tls is None:
            raise VahrError(f"broker {url} needs --cert, --key and --ca for mTLS")
        self._client = MqttClient(
            MqttEndpoint(
                host=address.host, port=address.port, credentials=tls if address.tls else None
            ),
            client_id=client_id,
            session_expiry_s=SESSION_EXPIRY_S,
            will=will,
        )
        # Robots retain their last `delivered` event; a retained message replays the past
        # when the recorder (re)subscribes, and logging it inside a task would count an old
        # delivery.
        for topic_filter in WIRE_TOPICS:
            self._client.subscribe(topic_filter, on_message, retained=False)

    def start(self) -> None:
        self._client.connect()

    def stop(self) -> None:
        self._client.stop()

    def publish(self, topic: str, payload: bytes, *, retain: bool = False) -> None:
        self._client.publish(topic, payload, retain=retain)
