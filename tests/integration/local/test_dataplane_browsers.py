"""The data plane against what a web page can make the operator's browser send: real
requests on the wire (and from a real headless Chromium) are refused and move nothing,
while boto3, unmodified and signing with dummy credentials, still publishes and reads.

"Move nothing" is observed where a robot would observe it: a service client subscribed to
every command topic sees no message, the shadow keeps its version, a local route is never
called. Each test ends with a genuine publish (a marker) so that what was refused had every
chance to arrive first: the broker keeps one publisher's order.
"""

from __future__ import annotations

import http.client
import http.server
import json
import threading
from typing import TYPE_CHECKING, Any

import boto3
import pytest
from playwright.sync_api import sync_playwright

from tests.integration.local.shadow_clients import unique_thing
from tests.support.browser import launch
from vahr.plumbing.client import call
from vahr.plumbing.mqtt import MqttClient
from vahr.plumbing.ports import free_port
from vahr.protocol import topics
from vahr.twin.shadow_store import ShadowError

if TYPE_CHECKING:
    from collections.abc import Iterator

    from vahr.twin.stack import LocalStack

FLEET_CMD_PATH = "/topics/vahr%2Ffleet%2Fcmd?qos=1"
STOP_EVERYTHING = b'{"id":"drive-by-1","action":"stop","params":{}}'
MARKER = b'{"id":"marker","action":"ping","params":{}}'


@pytest.fixture
def iot_data(
    local_stack: LocalStack, aws_credentials: None, monkeypatch: pytest.MonkeyPatch
) -> Any:
    monkeypatch.setenv("AWS_ENDPOINT_URL_IOT_DATA_PLANE", local_stack.api_url)
    return boto3.client("iot-data")


class Commands:
    """Every command topic as a robot would hear it, through a service client."""

    def __init__(self, stack: LocalStack) -> None:
        self.heard: list[tuple[str, bytes]] = []
        self._marker = threading.Event()
        self._client = MqttClient(stack.service_endpoint()).connect()
        for topic_filter in (topics.FLEET_CMD, topics.ALL_ROBOT_CMDS):
            self._client.subscribe(topic_filter, self._record)

    def _record(self, topic: str, payload: bytes) -> None:
        self.heard.append((topic, payload))
        if payload == MARKER:
            self._marker.set()

    def after_marker(self, iot_data: Any) -> list[tuple[str, bytes]]:
        """Publish the marker with boto3; everything heard up to it."""
        iot_data.publish(topic=topics.FLEET_CMD, qos=1, payload=MARKER)
        assert self._marker.wait(10), "boto3's publish never arrived"
        return self.heard

    def close(self) -> None:
        self._client.stop()


@pytest.fixture
def commands(local_stack: LocalStack) -> Iterator[Commands]:
    watcher = Commands(local_stack)
    yield watcher
    watcher.close()


def send(
    stack: LocalStack, method: str, path: str, body: bytes = b"", **headers: str
) -> tuple[int, dict[str, Any]]:
    """One raw request; `headers` with `_` for `-` (Host defaults to the API's own)."""
    named = {name.replace("_", "-"): value for name, value in headers.items()}
    named.setdefault("Host", f"127.0.0.1:{stack.config.api_port}")
    connection = http.client.HTTPConnection("127.0.0.1", stack.config.api_port, timeout=10)
    try:
        connection.putrequest(method, path, skip_host=True, skip_accept_encoding=True)
        for name, value in {**named, "Content-Length": str(len(body))}.items():
            connection.putheader(name, value)
        connection.endheaders(body)
        answer = connection.getresponse()
        return answer.status, json.loads(answer.read() or b"{}")
    finally:
        connection.close()


# What a page sends with `fetch(url, {method: "POST", mode: "no-cors", body: "..."})`.
NO_CORS_FROM_ELSEWHERE = {
    "Content_Type": "text/plain;charset=UTF-8",
    "Origin": "http://attacker.example",
    "Sec_Fetch_Site": "cross-site",
    "Sec_Fetch_Mode": "no-cors",
}


def test_a_cross_site_text_plain_post_commands_no_robot(
    local_stack: LocalStack, commands: Commands, iot_data: Any
) -> None:
    # When a page elsewhere posts a fleet-wide stop as text/plain, with and without the
    # headers a browser adds (an older browser, a form), and to one robot's topic
    answers = [
        send(local_stack, "POST", FLEET_CMD_PATH, STOP_EVERYTHING, **NO_CORS_FROM_ELSEWHERE),
        send(local_stack, "POST", FLEET_CMD_PATH, STOP_EVERYTHING, Content_Type="text/plain"),
        send(local_stack, "POST", FLEET_CMD_PATH, STOP_EVERYTHING),
        send(
            local_stack,
            "POST",
            "/topics/vahr%2Frobots%2Fplacebot1%2Fcmd?qos=1",
            STOP_EVERYTHING,
            Content_Type="application/x-www-form-urlencoded",
            Origin="null",
        ),
    ]
    # Then each is refused, in AWS's error shape
    assert [status for status, _ in answers] == [403, 415, 415, 403]
    assert answers[0][1] == {
        "code": 403,
        "message": "requests from http://attacker.example are not accepted",
    }
    assert (
        answers[1][1]["message"] == "a write must send application/json or be signed with AWS SigV4"
    )
    # And no robot heard anything but boto3's genuine command that came after
    assert commands.after_marker(iot_data) == [(topics.FLEET_CMD, MARKER)]


def test_a_drive_by_desired_command_leaves_the_shadow_as_it_was(
    local_stack: LocalStack, iot_data: Any
) -> None:
    thing = unique_thing()
    iot_data.update_thing_shadow(thingName=thing, payload=b'{"state":{"reported":{"zone":"A"}}}')
    before = json.loads(iot_data.get_thing_shadow(thingName=thing)["payload"].read())
    desired = b'{"state":{"desired":{"command":{"id":"drive-by-2","action":"stop"}}}}'
    # When a page posts a desired command to the robot's shadow, as text/plain or with a
    # foreign Origin, and a page that rebound its name posts JSON
    statuses = [
        send(local_stack, "POST", f"/things/{thing}/shadow", desired, **NO_CORS_FROM_ELSEWHERE)[0],
        send(local_stack, "POST", f"/things/{thing}/shadow", desired, Content_Type="text/plain")[0],
        send(
            local_stack,
            "POST",
            f"/things/{thing}/shadow",
            desired,
            Host=f"attacker.example:{local_stack.config.api_port}",
            Content_Type="application/json",
        )[0],
        send(local_stack, "DELETE", f"/things/{thing}/shadow", Origin="http://attacker.example")[0],
    ]
    assert statuses == [403, 415, 421, 403]
    # Then the shadow is the one boto3 wrote: same version, no desired state
    after = json.loads(iot_data.get_thing_shadow(thingName=thing)["payload"].read())
    assert after["version"] == before["version"]
    assert "desired" not in after["state"]


def test_a_rebound_name_reads_no_shadow(local_stack: LocalStack, iot_data: Any) -> None:
    thing = unique_thing()
    iot_data.update_thing_shadow(thingName=thing, payload=b'{"state":{"reported":{"zone":"B"}}}')
    # When a page at attacker.example, its name now resolving to 127.0.0.1, reads the shadow
    status, body = send(
        local_stack,
        "GET",
        f"/things/{thing}/shadow",
        Host=f"attacker.example:{local_stack.config.api_port}",
    )
    # Then it is refused, and the answer holds nothing of the shadow
    assert status == 421
    assert body == {
        "code": 421,
        "message": f"this server does not answer to the host 'attacker.example:{local_stack.config.api_port}'",
    }
    # Nor does a fetch that says it comes from another site, whatever its Host
    status, body = send(local_stack, "GET", f"/things/{thing}/shadow", Sec_Fetch_Site="cross-site")
    assert status == 403
    assert "state" not in body


def test_a_local_route_is_not_called_by_a_page(local_stack: LocalStack) -> None:
    assert local_stack.dataplane is not None
    calls: list[dict[str, Any]] = []
    path = f"/vahr/probe-{unique_thing()}"
    local_stack.dataplane.local_routes[("POST", path)] = lambda body: (
        calls.append(body),
        (200, {"ok": True}),
    )[1]
    try:
        # When a page posts to it as text/plain (as it could to /vahr/say or /vahr/fault)
        status, _ = send(
            local_stack, "POST", path, b'{"utterance":"stop all robots"}', **NO_CORS_FROM_ELSEWHERE
        )
        assert status == 403
        status, _ = send(
            local_stack, "POST", path, b'{"utterance":"stop all robots"}', Content_Type="text/plain"
        )
        assert status == 415
        assert calls == []
        # While the repository's own client (vahr say, the station, vahr fault) is served
        assert call(local_stack.api_url, "POST", path, {"utterance": "where are the robots"}) == {
            "ok": True
        }
        assert calls == [{"utterance": "where are the robots"}]
    finally:
        del local_stack.dataplane.local_routes[("POST", path)]


def test_boto3_unmodified_still_publishes_and_reads(
    local_stack: LocalStack, commands: Commands, iot_data: Any
) -> None:
    thing = unique_thing()
    command = b'{"id":"genuine-1","action":"ping","params":{}}'
    iot_data.publish(topic=topics.robot_cmd("placebot1"), qos=1, payload=command)
    iot_data.update_thing_shadow(thingName=thing, payload=b'{"state":{"desired":{"zone":"C"}}}')
    shadow = json.loads(iot_data.get_thing_shadow(thingName=thing)["payload"].read())
    assert shadow["state"]["desired"] == {"zone": "C"}
    iot_data.delete_thing_shadow(thingName=thing)
    assert commands.after_marker(iot_data) == [
        (topics.robot_cmd("placebot1"), command),
        (topics.FLEET_CMD, MARKER),
    ]


# -- a real browser ------------------------------------------------------------------------

ATTACK_PAGE = """<!doctype html><title>cat pictures</title><script>
window.attack = async (api) => {
  const tries = [
    fetch(api + "/topics/vahr%%2Ffleet%%2Fcmd?qos=1", {method: "POST", mode: "no-cors", body: %(stop)s}),
    fetch(api + "/things/placebot1/shadow", {method: "POST", mode: "no-cors",
      body: '{"state":{"desired":{"command":{"id":"drive-by-3","action":"stop"}}}}'}),
    fetch(api + "/vahr/say", {method: "POST", mode: "no-cors", body: '{"utterance":"stop"}'}),
  ];
  let read = "refused";
  try { read = await (await fetch(api + "/things/placebot1/shadow")).text(); } catch (e) {}
  await Promise.allSettled(tries);
  return read;
};
</script>"""


def _shadow_version(stack: LocalStack, thing: str) -> int | None:
    assert stack.store is not None
    try:
        version: int = stack.store.get(thing)["version"]
    except ShadowError:
        return None
    return version


class _AttackPage(http.server.BaseHTTPRequestHandler):
    def do_GET(self) -> None:  # noqa: N802
        body = (ATTACK_PAGE % {"stop": json.dumps(STOP_EVERYTHING.decode())}).encode()
        self.send_response(200)
        self.send_header("Content-Type", "text/html")
        self.send_header("Content-Length", str(len(body)))
        self.end_headers()
        self.wfile.write(body)

    def log_message(self, format: str, *args: object) -> None:  # noqa: A002
        pass


def test_a_page_open_in_chromium_moves_no_robot(
    local_stack: LocalStack, commands: Commands, iot_data: Any
) -> None:
    from http.server import ThreadingHTTPServer

    before = _shadow_version(local_stack, "placebot1")
    server = ThreadingHTTPServer(("127.0.0.1", free_port()), _AttackPage)
    serving = threading.Thread(target=server.serve_forever, kwargs={"poll_interval": 0.1})
    serving.start()
    try:
        with sync_playwright() as playwright:
            browser = launch(playwright)
            try:
                page = browser.new_page()
                # A page on another site (localhost is not 127.0.0.1's site) and one on
                # the same site but another port: the operator has both open
                for origin in (
                    f"http://localhost:{server.server_port}",
                    f"http://127.0.0.1:{server.server_port}",
                ):
                    page.goto(f"{origin}/")
                    read = page.evaluate("api => window.attack(api)", local_stack.api_url)
                    # (A browser keeps a cross-origin answer from the page anyway; a
                    # rebound name is what would let it read, refused above.)
                    assert read == "refused"
            finally:
                browser.close()
    finally:
        server.shutdown()
        serving.join(5)
        server.server_close()
    assert commands.after_marker(iot_data) == [(topics.FLEET_CMD, MARKER)]
    assert _shadow_version(local_stack, "placebot1") == before


def test_a_configured_host_name_is_served(local_stack: LocalStack) -> None:
    # Given the data plane told of a proxy's or a tunnel's name (vahr up --api-host)
    from vahr.twin.dataplane import DataPlaneServer

    assert local_stack.dataplane is not None
    port = free_port()
    with DataPlaneServer(local_stack.dataplane, port, hosts=frozenset({"robots.lab"})):
        for host, expected in ((f"robots.lab:{port}", 200), (f"other.lab:{port}", 421)):
            connection = http.client.HTTPConnection("127.0.0.1", port, timeout=10)
            try:
                connection.request("GET", "/vahr/health", headers={"Host": host})
                assert connection.getresponse().status == expected, host
            finally:
                connection.close()
