"""Test-side MQTT parts for the agent's integration tests: a wire tap and a shadow responder.

`WireTap` is a paho client that records every message on the broker (including the
`$aws/...` shadow topics) and publishes as the skill or a console would. `ShadowResponder`
answers shadow `update`/`get` requests the way AWS IoT does (accepted, delta, 404, and a
409 on request), so the agent's shadow traffic can be checked without the cloud.
"""

from __future__ import annotations

import contextlib
import json
import os
import signal
import socket
import subprocess
import sys
import threading
import time
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import paho.mqtt.client as paho
from paho.mqtt.enums import CallbackAPIVersion, MQTTProtocolVersion

from vahr.plumbing.lifetime import spawn

if TYPE_CHECKING:
    from collections.abc import Callable

ROOT = Path(__file__).resolve().parents[3]
# The robot-agent of the venv running the tests (.venv, or .venv-ros2 for the nav2 backend).
AGENT = Path(sys.executable).with_name("robot-agent")


@dataclass(frozen=True)
class Message:
    topic: str
    payload: bytes
    retain: bool
    at: float

    def json(self) -> Any:
        return json.loads(self.payload)


def _client(port: int, client_id: str) -> paho.Client:
    client = paho.Client(
        CallbackAPIVersion.VERSION2, client_id=client_id, protocol=MQTTProtocolVersion.MQTTv5
    )

    def nodelay(client: paho.Client, userdata: Any, sock: socket.socket) -> None:
        # paho does not set TCP_NODELAY; without it back-to-back publishes stall on Nagle.
        sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)

    client.on_socket_open = nodelay
    connected = threading.Event()
    client.on_connect = lambda *a: connected.set()
    client.connect("127.0.0.1", port, keepalive=30)
    client.loop_start()
    if not connected.wait(5):
        client.loop_stop()
        raise TimeoutError("test client could not connect")
    return client


class WireTap:
    """Everything published on the broker, in arrival order, with waits that time out."""

    def __init__(self, port: int) -> None:
        self.port = port
        self.messages: list[Message] = []
        self._cond = threading.Condition()
        self._client = _client(port, f"wiretap-{os.getpid()}-{time.monotonic_ns()}")
        self._client.on_message = self._on_message
        subscribed = threading.Event()
        self._client.on_subscribe = lambda *a: subscribed.set()
        self._client.subscribe([("#", 1), ("$aws/things/+/shadow/#", 1)])
        if not subscribed.wait(5):
            raise TimeoutError("wire tap could not subscribe")

    def _on_message(self, client: paho.Client, userdata: Any, message: paho.MQTTMessage) -> None:
        with self._cond:
            self.messages.append(
                Message(
                    message.topic, bytes(message.payload), bool(message.retain), time.monotonic()
                )
            )
            self._cond.notify_all()

    def publish(
        self, topic: str, payload: bytes | str | dict[str, Any], *, retain: bool = False
    ) -> None:
        if isinstance(payload, dict):
            payload = json.dumps(payload)
        info = self._client.publish(topic, payload, qos=1, retain=retain)
        info.wait_for_publish(5)

    def wait_for(
        self, predicate: Callable[[Message], bool], timeout_s: float = 10.0, *, after: int = 0
    ) -> Message:
        """The first message (from index `after`) that satisfies `predicate`."""
        deadline = time.monotonic() + timeout_s
        with self._cond:
            while True:
                for message in self.messages[after:]:
                    if predicate(message):
                        return message
                remaining = deadline - time.monotonic()
                if remaining <= 0:
                    seen = [m.topic for m in self.messages[after:]][-20:]
                    raise TimeoutError(
                        f"no matching message within {timeout_s} s; last topics {seen}"
                    )
                self._cond.wait(remaining)

    def events(self, thing: str, command_id: str | None = None) -> list[dict[str, Any]]:
        with self._cond:
            found = [m.json() for m in self.messages if m.topic == f"vahr/robots/{thing}/events"]
        return [e for e in found if command_id is None or e.get("command_id") == command_id]

    def event(
        self,
        thing: str,
        kind: str,
        command_id: str | None = None,
        timeout_s: float = 10.0,
        after: int = 0,
    ) -> dict[str, Any]:
        def match(m: Message) -> bool:
            if m.topic != f"vahr/robots/{thing}/events":
                return False
            body = m.json()
            return bool(
                body["event"] == kind
                and (command_id is None or body.get("command_id") == command_id)
            )

        result: dict[str, Any] = self.wait_for(match, timeout_s, after=after).json()
        return result

    def shadow_updates(self, thing: str) -> list[dict[str, Any]]:
        with self._cond:
            return [
                m.json()
                for m in self.messages
                if m.topic == f"$aws/things/{thing}/shadow/update" and b'"reported"' in m.payload
            ]

    def reported(
        self,
        thing: str,
        predicate: Callable[[dict[str, Any]], bool],
        timeout_s: float = 10.0,
        after: int = 0,
    ) -> dict[str, Any]:
        """The first reported state the agent published that satisfies `predicate`."""

        def match(m: Message) -> bool:
            if m.topic != f"$aws/things/{thing}/shadow/update" or b'"reported"' not in m.payload:
                return False
            return predicate(m.json()["state"]["reported"])

        result: dict[str, Any] = self.wait_for(match, timeout_s, after=after).json()["state"][
            "reported"
        ]
        return result

    def retained(self, topic: str, timeout_s: float = 5.0) -> dict[str, Any] | None:
        """The retained message a new subscriber to `topic` gets, or None."""
        found: list[bytes] = []
        got = threading.Event()
        client = _client(self.port, f"retained-{time.monotonic_ns()}")

        def on_message(client: paho.Client, userdata: Any, message: paho.MQTTMessage) -> None:
            if message.retain:
                found.append(bytes(message.payload))
                got.set()

        client.on_message = on_message
        try:
            client.subscribe(topic, qos=1)
            got.wait(timeout_s)
        finally:
            client.disconnect()
            client.loop_stop()
        return json.loads(found[0]) if found else None

    def mark(self) -> int:
        with self._cond:
            return len(self.messages)

    def close(self) -> None:
        self._client.disconnect()
        self._client.loop_stop()


class ShadowResponder:
    """A minimal AWS-like shadow service for the agent's requests (classic shadows only)."""

    def __init__(self, port: int) -> None:
        self.documents: dict[str, dict[str, Any]] = {}
        self.versions: dict[str, int] = {}
        self.conflicts_to_inject = 0
        self._lock = threading.Lock()
        self._written = threading.Condition(self._lock)
        self._client = _client(port, f"shadow-responder-{os.getpid()}-{time.monotonic_ns()}")
        self._client.on_message = self._on_message
        subscribed = threading.Event()
        self._client.on_subscribe = lambda *a: subscribed.set()
        self._client.subscribe(
            [("$aws/things/+/shadow/update", 1), ("$aws/things/+/shadow/get", 1)]
        )
        if not subscribed.wait(5):
            raise TimeoutError("shadow responder could not subscribe")

    def _answer(self, topic: str, body: dict[str, Any]) -> None:
        self._client.publish(topic, json.dumps(body), qos=1)

    def _on_message(self, client: paho.Client, userdata: Any, message: paho.MQTTMessage) -> None:
        thing = message.topic.split("/")[2]
        base = f"$aws/things/{thing}/shadow"
        with self._lock:
            if message.topic.endswith("/get"):
                if thing not in self.documents:
                    self._answer(
                        f"{base}/get/rejected",
                        {"code": 404, "message": "No shadow exists with name: '" + thing + "'"},
                    )
                else:
                    self._answer(f"{base}/get/accepted", self._document(thing))
                return
            request = json.loads(message.payload)
            if self.conflicts_to_inject > 0 and "reported" in request.get("state", {}):
                self.conflicts_to_inject -= 1
                self._answer(
                    f"{base}/update/rejected",
                    {
                        "code": 409,
                        "message": "Version conflict",
                        "clientToken": request.get("clientToken"),
                    },
                )
                return
            self.write(thing, request.get("state", {}))
            self._answer(
                f"{base}/update/accepted",
                {"state": request.get("state"), "version": self.versions[thing]},
            )
            delta = self._delta(thing)
            if delta and "desired" in request.get("state", {}):
                self._answer(
                    f"{base}/update/delta", {"state": delta, "version": self.versions[thing]}
                )

    def write(self, thing: str, state: dict[str, Any]) -> None:
        document = self.documents.setdefault(thing, {})
        for section in ("reported", "desired"):
            if section in state:
                if state[section] is None:
                    document.pop(section, None)
                else:
                    document.setdefault(section, {}).update(state[section])
        self.versions[thing] = self.versions.get(thing, 0) + 1
        self._written.notify_all()

    def document(
        self, thing: str, predicate: Callable[[dict[str, Any]], bool], timeout_s: float = 5.0
    ) -> dict[str, Any]:
        """The thing's stored document once it satisfies `predicate`.

        The test's wire tap and this responder are separate clients, so the tap may see an
        update before the responder has stored it.
        """
        with self._written:
            if not self._written.wait_for(
                lambda: predicate(self.documents.get(thing, {})), timeout_s
            ):
                raise TimeoutError(f"{thing}'s shadow: {self.documents.get(thing)}")
            return self.documents[thing]

    def set_desired(self, thing: str, desired: dict[str, Any]) -> None:
        """Write desired state as the skill would over the data plane (no MQTT request)."""
        with self._lock:
            self.write(thing, {"desired": desired})
            delta = self._delta(thing)
        if delta:
            self._answer(
                f"$aws/things/{thing}/shadow/update/delta",
                {"state": delta, "version": self.versions[thing]},
            )

    def _delta(self, thing: str) -> dict[str, Any]:
        document = self.documents.get(thing, {})
        desired, reported = document.get("desired", {}), document.get("reported", {})
        return {k: v for k, v in desired.items() if reported.get(k) != v}

    def _document(self, thing: str) -> dict[str, Any]:
        document = self.documents[thing]
        state: dict[str, Any] = {k: v for k, v in document.items()}
        delta = self._delta(thing)
        if delta:
            state["delta"] = delta
        return {"state": state, "version": self.versions[thing]}

    def close(self) -> None:
        self._client.disconnect()
        self._client.loop_stop()


class AgentProcess:
    """`robot-agent run` as a real subprocess; `stop()` sends SIGTERM and returns the exit code."""

    def __init__(self, *args: str, state_dir: Path, log_file: Path) -> None:
        self.args = [str(AGENT), "run", "--state-dir", str(state_dir), *args]
        self.log_file = log_file
        self._log = log_file.open("ab")
        # Tied to the test run's life: a killed pytest leaves no robot behind.
        self.process = spawn(
            self.args,
            started_for=state_dir,
            stdin=subprocess.DEVNULL,
            stdout=self._log,
            stderr=subprocess.STDOUT,
            cwd=ROOT,
            # The checkout on the path, so `--voice tests....:factory` can name a test double.
            env={**os.environ, "PYTHONPATH": str(ROOT)},
        )

    def log(self) -> str:
        return self.log_file.read_text(errors="replace")

    def stop(self, sig: int = signal.SIGTERM, timeout_s: float = 10.0) -> int:
        if self.process.poll() is None:
            self.process.send_signal(sig)
        try:
            code = self.process.wait(timeout=timeout_s)
        except subprocess.TimeoutExpired:
            self.process.kill()
            code = self.process.wait(timeout=5)
        self._log.close()
        return code

    def kill(self) -> None:
        with contextlib.suppress(ProcessLookupError):
            self.process.kill()
        self.process.wait(timeout=5)
        self._log.close()


def command(
    command_id: str, action: str, params: dict[str, Any] | None = None, **extra: Any
) -> dict[str, Any]:
    body: dict[str, Any] = {
        "id": command_id,
        "action": action,
        "params": params or {},
        "issued_at": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime()),
        "source": "console",
    }
    body.update(extra)
    return body


__all__ = ["AgentProcess", "Message", "ShadowResponder", "WireTap", "command"]
