"""The paho-mqtt adapter of the session: records the wire into the log and sends commands.

It subscribes to every robot's events and to every command topic (robot and fleet), and
hands each message to a callback. The MQTT session is persistent (clean session off, a
client id fixed per experiment session), so while the recorder is down after a crash the
broker queues the QoS 1 messages it misses and delivers them when the session resumes.
The keyboard-and-mouse method's console publishes its
commands here too (QoS 1, source "console"), exactly as the skill would.
"""

from __future__ import annotations

import socket
import ssl
import threading
from dataclasses import dataclass
from typing import TYPE_CHECKING
from urllib.parse import urlparse

import paho.mqtt.client as mqtt

from vahr.errors import VahrError
from vahr.protocol import topics

if TYPE_CHECKING:
    from collections.abc import Callable
    from pathlib import Path

CONNECT_TIMEOUT_S = 10.0
PUBLISH_TIMEOUT_S = 5.0
WIRE_TOPICS = (topics.ALL_EVENTS, "vahr/robots/+/cmd", topics.FLEET_CMD)


@dataclass(frozen=True)
class TlsFiles:
    """Client certificate, key and CA for an mTLS broker (AWS IoT Core, `vahr up`'s mqtts)."""

    cert_file: Path
    key_file: Path
    ca_file: Path


def parse_broker_url(url: str) -> tuple[str, int, bool]:
    """`mqtt://HOST[:PORT]` or `mqtts://HOST[:PORT]` -> (host, port, tls)."""
    parsed = urlparse(url)
    if parsed.scheme not in ("mqtt", "mqtts") or not parsed.hostname:
        raise VahrError(f"broker {url!r} is not an mqtt:// or mqtts://HOST:PORT URL")
    tls = parsed.scheme == "mqtts"
    return parsed.hostname, parsed.port or (8883 if tls else 1883), tls


class Bus:
    """One MQTT connection: subscribed to the wire topics, able to publish commands."""

    def __init__(
        self,
        url: str,
        on_message: Callable[[str, bytes], None],
        client_id: str,
        tls: TlsFiles | None = None,
    ) -> None:
        self._host, self._port, secure = parse_broker_url(url)
        if secure and tls is None:
            raise VahrError(f"broker {url} needs --cert, --key and --ca for mTLS")
        self._on_message = on_message
        self._subscribed = threading.Event()
        self._client = mqtt.Client(
            mqtt.CallbackAPIVersion.VERSION2,
            client_id=client_id,
            protocol=mqtt.MQTTv311,
            clean_session=False,
        )
        self._client.on_connect = self._on_connect
        self._client.on_message = self._on_message_raw
        self._client.on_subscribe = self._on_subscribe
        if secure and tls is not None:
            for name in ("cert_file", "key_file", "ca_file"):
                if not getattr(tls, name).is_file():
                    raise VahrError(f"{name.replace('_', ' ')} {getattr(tls, name)} does not exist")
            self._client.tls_set(
                ca_certs=str(tls.ca_file), certfile=str(tls.cert_file), keyfile=str(tls.key_file)
            )

    def start(self) -> None:
        try:
            self._client.connect(self._host, self._port, keepalive=30)
        except ssl.SSLError as err:
            raise VahrError(
                f"TLS handshake with {self._host}:{self._port} failed: {err.reason or err}"
            ) from err
        except OSError as err:
            raise VahrError(f"cannot reach the broker at {self._host}:{self._port}: {err}") from err
        sock = self._client.socket()
        if isinstance(sock, socket.socket):
            # paho does not set TCP_NODELAY; without it back-to-back publishes stall ~40 ms.
            sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
        self._client.loop_start()
        if not self._subscribed.wait(CONNECT_TIMEOUT_S):
            self.stop()
            raise VahrError(
                f"the broker at {self._host}:{self._port} did not accept the subscription "
                f"within {CONNECT_TIMEOUT_S:.0f} s"
            )

    def stop(self) -> None:
        self._client.disconnect()
        self._client.loop_stop()

    def publish(self, topic: str, payload: bytes) -> None:
        info = self._client.publish(topic, payload, qos=1)
        info.wait_for_publish(PUBLISH_TIMEOUT_S)
        if not info.is_published():
            raise VahrError(f"the broker did not acknowledge a publish to {topic}")

    def _on_connect(
        self,
        client: mqtt.Client,
        userdata: object,
        flags: object,
        reason: object,
        properties: object,
    ) -> None:
        client.subscribe([(topic, 1) for topic in WIRE_TOPICS])

    def _on_subscribe(
        self, client: mqtt.Client, userdata: object, mid: int, reasons: object, properties: object
    ) -> None:
        self._subscribed.set()

    # Robots retain their last `delivered` event; a retained message replays the past when
    # the recorder (re)subscribes, and logging it inside a task would count an old delivery.
    def _on_message_raw(
        self, client: mqtt.Client, userdata: object, message: mqtt.MQTTMessage
    ) -> None:
        if message.retain:
            return
        self._on_message(message.topic, bytes(message.payload))
