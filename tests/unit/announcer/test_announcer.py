"""The announcer function under moto (Secrets Manager, DynamoDB) against a stand-in of Login
with Amazon and the Alexa Proactive Events API on 127.0.0.1, which checks each request the
way Amazon documents it. What a person would observe: one notification per fault, retries
on 401 and 429, and a failure that raises (so Lambda retries, then dead-letters it) with
one line in the log, never a crash of another kind."""

from __future__ import annotations

import json
import re
import threading
from datetime import UTC, datetime, timedelta
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from pathlib import Path
from typing import TYPE_CHECKING, Any
from urllib.parse import parse_qs

import boto3
import pytest
from botocore.exceptions import ClientError
from moto import mock_aws
from moto.core import DEFAULT_ACCOUNT_ID
from moto.iotdata.models import iotdata_backends
from msgspec.structs import replace

from announcer import app
from announcer.aws import AnnouncementTopic, SkillCredentials, StateStore
from announcer.config import AnnouncerConfig, events_url
from announcer.errors import AnnouncerError, ConfigError, DeliveryFailed
from announcer.proactive_events import ProactiveEvents
from tests.support.shared_models import default_session
from vahr.announce import settings_from
from vahr.announce.speech import Names
from vahr.protocol import topics
from vahr.protocol.announcements import decode_announcement

if TYPE_CHECKING:
    from collections.abc import Iterator

    from vahr.domain import Fleet

EVENTS = Path(__file__).resolve().parents[2] / "events"
REGION = "us-east-1"
CLIENT_ID = "amzn1.application-oa2-client.0123456789abcdef"
CLIENT_SECRET = "s3cr3t"
EVENTS_PATH = "/v1/proactiveEvents/stages/development"


def load_event(name: str) -> dict[str, Any]:
    """A real-shaped JSON document from tests/events/ by name."""
    loaded: dict[str, Any] = json.loads((EVENTS / f"{name}.json").read_text())
    return loaded


TOKEN = load_event("lwa_token")["access_token"]


class AlexaStandIn(ThreadingHTTPServer):
    """LWA's token endpoint and the Proactive Events endpoint, answering from a script."""

    def __init__(self) -> None:
        super().__init__(("127.0.0.1", 0), _Handler)
        self.script: list[tuple[int, dict[str, Any], dict[str, str]]] = []
        self.events: list[dict[str, Any]] = []
        self.tokens_issued = 0
        self.problems: list[str] = []
        self.valid_tokens = {TOKEN}

    @property
    def url(self) -> str:
        return f"http://127.0.0.1:{self.server_address[1]}"


class _Handler(BaseHTTPRequestHandler):
    server: AlexaStandIn

    def log_message(self, *args: object) -> None:
        pass

    def _answer(
        self, status: int, body: dict[str, Any], headers: dict[str, str] | None = None
    ) -> None:
        data = json.dumps(body).encode()
        self.send_response(status)
        self.send_header("Content-Type", "application/json")
        for name, value in (headers or {}).items():
            self.send_header(name, value)
        self.send_header("Content-Length", str(len(data)))
        self.end_headers()
        self.wfile.write(data)

    def do_POST(self) -> None:  # noqa: N802 - http.server's name
        body = self.rfile.read(int(self.headers["Content-Length"]))
        if self.path == "/auth/o2/token":
            return self._token(body)
        if self.path == EVENTS_PATH:
            return self._event(body)
        self._answer(404, {"message": "no such path"})

    def _token(self, body: bytes) -> None:
        form = {k: v[0] for k, v in parse_qs(body.decode()).items()}
        expected = {"grant_type": "client_credentials", "client_id": CLIENT_ID,
                    "client_secret": CLIENT_SECRET, "scope": "alexa::proactive_events"}  # fmt: skip
        if not self.headers["Content-Type"].startswith("application/x-www-form-urlencoded"):
            self.server.problems.append("token request is not form-encoded")
        if form != expected:
            return self._answer(
                401,
                {"error": "invalid_client", "error_description": "Client authentication failed"},
            )
        self.server.tokens_issued += 1
        self._answer(200, load_event("lwa_token"))

    def _event(self, body: bytes) -> None:
        auth = self.headers.get("Authorization", "")
        if auth.removeprefix("Bearer ") not in self.server.valid_tokens:
            return self._answer(
                401, {"code": "UNAUTHORIZED", "message": "The access token is invalid or expired."}
            )
        self.server.problems += check_event(json.loads(body), self.headers["Content-Type"])
        if self.server.script:
            status, answer, headers = self.server.script.pop(0)
            if status != 202:
                return self._answer(status, answer, headers)
        self.server.events.append(json.loads(body))
        self.send_response(202)
        self.send_header("Content-Length", "0")
        self.end_headers()


def check_event(event: dict[str, Any], content_type: str) -> list[str]:
    """The request as the Proactive Events API reference describes it."""
    problems = []
    if content_type != "application/json":
        problems.append(f"Content-Type {content_type}")
    if not re.fullmatch(r"[A-Za-z0-9~]{1,100}", event.get("referenceId", "")):
        problems.append(f"referenceId {event.get('referenceId')!r}")
    sent, expires = (
        datetime.fromisoformat(event[k].replace("Z", "+00:00")) for k in ("timestamp", "expiryTime")
    )
    if not timedelta(minutes=5) <= expires - sent <= timedelta(hours=24):
        problems.append("expiryTime must be 5 minutes to 24 hours after timestamp")
    if event["event"]["name"] != "AMAZON.MessageAlert.Activated":
        problems.append(f"event.name {event['event']['name']}")
    payload = event["event"]["payload"]
    if payload["state"]["status"] not in ("UNREAD", "FLAGGED") or payload["state"].get(
        "freshness"
    ) not in ("NEW", "OVERDUE"):
        problems.append(f"state {payload['state']}")
    group = payload["messageGroup"]
    if (
        not group["creator"]["name"]
        or not isinstance(group["count"], int)
        or group.get("urgency", "URGENT") != "URGENT"
    ):
        problems.append(f"messageGroup {group}")
    if event["relevantAudience"]["type"] not in ("Multicast", "Unicast"):
        problems.append(f"relevantAudience {event['relevantAudience']}")
    return problems


@pytest.fixture
def alexa() -> Iterator[AlexaStandIn]:
    server = AlexaStandIn()
    thread = threading.Thread(target=server.serve_forever, daemon=True)
    thread.start()
    try:
        yield server
    finally:
        server.shutdown()
        server.server_close()
        thread.join(timeout=5)


@pytest.fixture
def runtime(
    monkeypatch: pytest.MonkeyPatch, fleet: Fleet, alexa: AlexaStandIn
) -> Iterator[app.Runtime]:
    monkeypatch.setenv("AWS_DEFAULT_REGION", REGION)
    for name in ("AWS_PROFILE", "AWS_ENDPOINT_URL"):
        monkeypatch.delenv(name, raising=False)
    with mock_aws():
        default_session()
        secrets = boto3.client("secretsmanager", region_name=REGION)
        secrets.create_secret(Name="vahr/skill-messaging", SecretString=json.dumps(
            {"clientId": CLIENT_ID, "clientSecret": CLIENT_SECRET}))  # fmt: skip
        dynamodb = boto3.client("dynamodb", region_name=REGION)
        dynamodb.create_table(
            TableName="vahr-announcer", BillingMode="PAY_PER_REQUEST",
            KeySchema=[{"AttributeName": "id", "KeyType": "HASH"}],
            AttributeDefinitions=[{"AttributeName": "id", "AttributeType": "S"}],
        )  # fmt: skip
        config = AnnouncerConfig.from_env({
            "VAHR_ANNOUNCER_SECRET": "vahr/skill-messaging", "VAHR_ANNOUNCER_TABLE": "vahr-announcer",
            "VAHR_PROACTIVE_EVENTS_URL": alexa.url + EVENTS_PATH,
            "VAHR_LWA_TOKEN_URL": alexa.url + "/auth/o2/token",
        })  # fmt: skip
        yield app.Runtime(
            config=config,
            names=Names.of(fleet),
            store=StateStore(config.table),
            alexa=ProactiveEvents(
                token_url=config.token_url, events_url=config.events_url,
                credentials=SkillCredentials(config.secret), sleep=lambda s: None,
            ),
            topic=AnnouncementTopic(config.iot_data_endpoint),
        )  # fmt: skip


def test_a_stuck_robot_becomes_one_urgent_message_alert(
    runtime: app.Runtime, alexa: AlexaStandIn
) -> None:
    # Given the rule delivering placebot1's stuck event, then the failed event that ends it
    first = app.announce(load_event("iot_rule_robot_stuck"), runtime)
    second = app.announce(load_event("iot_rule_robot_failed_stuck"), runtime)
    # Then Alexa got one notification, well-formed, for everyone, from placebot one
    assert alexa.problems == []
    [sent] = alexa.events
    assert len(first["told"]) == 1 and second["told"] == []
    assert sent["referenceId"] == first["told"][0]
    assert sent["event"]["payload"]["messageGroup"] == {
        "creator": {"name": "placebot one"}, "count": 1, "urgency": "URGENT",
    }  # fmt: skip
    assert sent["relevantAudience"] == {"type": "Multicast", "payload": {}}
    assert alexa.tokens_issued == 1


def published() -> list[tuple[str, bytes]]:
    """What the function published on AWS IoT, as moto recorded it."""
    return list(iotdata_backends[DEFAULT_ACCOUNT_ID][REGION].published_payloads)


def test_each_announcement_alexa_took_is_published_for_the_operator_station(
    runtime: app.Runtime, alexa: AlexaStandIn
) -> None:
    # Given a stuck robot told, and its redelivered failed event (the same fault)
    first = app.announce(load_event("iot_rule_robot_stuck"), runtime)
    app.announce(load_event("iot_rule_robot_failed_stuck"), runtime)
    # Then the station's topic got the one announcement, as the local stack sends it
    [(topic, payload)] = published()
    assert topic == topics.ASSISTANT_ANNOUNCEMENTS
    told = decode_announcement(payload)
    assert told.id == first["told"][0] == alexa.events[0]["referenceId"]
    assert told.speech == "Placebot one is stuck on its way to zone B and needs your help."


class RefusedPublish:
    def publish(self, **request: Any) -> None:
        raise ClientError({"Error": {"Code": "ForbiddenException", "Message": "denied"}}, "Publish")


def test_a_refused_publish_raises_so_the_event_is_retried_and_nothing_is_lost(
    runtime: app.Runtime, alexa: AlexaStandIn
) -> None:
    # Given a topic IoT refuses
    refused = replace(runtime, topic=AnnouncementTopic(None, client=RefusedPublish()))
    # Then the invocation raises in one line naming the topic, and saves no state
    with pytest.raises(
        DeliveryFailed,
        match=r"^cannot publish announcement vahr~stuck~\w+ on vahr/assistant/announcements: ",
    ):
        app.announce(load_event("iot_rule_robot_stuck"), refused)
    # And the retry tells it again: Alexa knows the duplicate, the station hears it once
    alexa.script = [(409, {"message": "duplicate referenceId"}, {})]
    again = app.announce(load_event("iot_rule_robot_stuck"), runtime)
    assert len(again["told"]) == 1 and len(published()) == 1


def test_offline_presence_is_told_and_the_token_is_reused(
    runtime: app.Runtime, alexa: AlexaStandIn
) -> None:
    app.announce(load_event("iot_rule_robot_stuck"), runtime)
    told = app.announce(load_event("iot_rule_presence_offline"), runtime)
    assert len(told["told"]) == 1
    assert [e["event"]["payload"]["messageGroup"]["creator"]["name"] for e in alexa.events] == [
        "placebot one", "placebot two",
    ]  # fmt: skip
    assert alexa.tokens_issued == 1


def test_an_expired_token_is_renewed_once_and_the_event_goes_through(
    runtime: app.Runtime, alexa: AlexaStandIn, caplog: pytest.LogCaptureFixture
) -> None:
    # Given a warm function still holding a token Alexa no longer accepts
    app.announce(load_event("iot_rule_robot_stuck"), runtime)
    runtime.alexa._token = ("Atc|expired", float("inf"))
    alexa.tokens_issued = 0
    told = app.announce(load_event("iot_rule_presence_offline"), runtime)
    # Then 401 was logged with Alexa's reason, a new token fetched, and the event delivered
    assert len(told["told"]) == 1 and len(alexa.events) == 2
    assert alexa.tokens_issued == 1
    assert "401" in caplog.text and "invalid or expired" in caplog.text


def test_429_is_retried_after_the_wait_alexa_asks_for(
    runtime: app.Runtime, alexa: AlexaStandIn, caplog: pytest.LogCaptureFixture
) -> None:
    waits: list[float] = []
    runtime.alexa._sleep = waits.append
    alexa.script = [(429, load_event("proactive_events_429"), {"Retry-After": "2"})]
    told = app.announce(load_event("iot_rule_robot_stuck"), runtime)
    assert len(told["told"]) == 1 and len(alexa.events) == 1
    assert waits == [2.0]
    assert "429" in caplog.text and "more calls than the allowed limit" in caplog.text


def test_throttled_past_every_attempt_raises_and_nothing_is_lost(
    runtime: app.Runtime, alexa: AlexaStandIn
) -> None:
    # Given Alexa throttling every attempt
    busy = (429, load_event("proactive_events_429"), {})
    alexa.script = [busy, busy, busy]
    # Then the handler raises (Lambda retries the event, then dead-letters it)
    with pytest.raises(DeliveryFailed, match=r"after 3 attempts \(429: The client has made"):
        app.announce(load_event("iot_rule_robot_stuck"), runtime)
    # And the fault was not marked told: the retry delivers it
    told = app.announce(load_event("iot_rule_robot_stuck"), runtime)
    assert len(told["told"]) == 1 and len(alexa.events) == 1


def test_403_is_not_retried_and_raises_with_alexas_reason(
    runtime: app.Runtime,
    alexa: AlexaStandIn,
    monkeypatch: pytest.MonkeyPatch,
    caplog: pytest.LogCaptureFixture,
) -> None:
    alexa.script = [(403, load_event("proactive_events_403"), {})]
    monkeypatch.setattr(app, "runtime", lambda: runtime)
    with pytest.raises(AnnouncerError) as raised:
        app.lambda_handler(load_event("iot_rule_robot_stuck"), None)
    assert str(raised.value) == (
        f"Alexa refused announcement {raised.value.args[0].split()[3]} "
        "(403: The authentication token does not have access to the resource.)"
    )
    assert alexa.script == [] and alexa.events == []
    [line] = [r.getMessage() for r in caplog.records if r.levelname == "ERROR"]
    assert line.startswith("announcement not delivered: Alexa refused") and "\n" not in line


def test_a_redelivered_event_after_a_lost_answer_is_a_duplicate_not_a_second_alert(
    runtime: app.Runtime, alexa: AlexaStandIn
) -> None:
    # Given Alexa accepted the event but the save failed (the next attempt decides again)
    alexa.script = [(409, {"message": "duplicate referenceId"}, {})]
    told = app.announce(load_event("iot_rule_robot_stuck"), runtime)
    assert len(told["told"]) == 1 and alexa.events == []


def test_a_scheduled_tick_tells_what_the_rate_limit_held_back(
    runtime: app.Runtime, alexa: AlexaStandIn, caplog: pytest.LogCaptureFixture
) -> None:
    # Given an announcer that may tell one thing in any half second
    settings = settings_from({"max_per_window": 1, "reserve_for_urgent": 0, "window_s": 0.5})
    now = [datetime.now(UTC)]
    rt = replace(runtime, config=replace(runtime.config, settings=settings), clock=lambda: now[0])
    # When a robot gets stuck and the other goes offline at once
    first = app.announce(load_event("iot_rule_robot_stuck"), rt)
    held = app.announce(load_event("iot_rule_presence_offline"), rt)
    assert len(first["told"]) == 1 and held["told"] == [] and held["held"] == 1
    # and no robot says anything more until the schedule's tick, after the window
    now[0] += timedelta(seconds=0.6)
    ticked = app.announce(load_event("eventbridge_schedule"), rt)
    # Then the tick tells what was held back, and takes the schedule for no robot's message
    assert len(ticked["told"]) == 1 and ticked["dropped"] == 0
    assert [e["event"]["payload"]["messageGroup"]["creator"]["name"] for e in alexa.events] == [
        "placebot one", "placebot two",
    ]  # fmt: skip
    assert "malformed" not in caplog.text


def test_a_tick_with_nothing_to_tell_writes_nothing(
    runtime: app.Runtime, alexa: AlexaStandIn
) -> None:
    app.announce(load_event("iot_rule_robot_stuck"), runtime)
    _, version = runtime.store.load()
    assert app.announce(load_event("eventbridge_schedule"), runtime)["told"] == []
    assert runtime.store.load()[1] == version
    assert len(alexa.events) == 1


def test_malformed_or_spoofed_messages_are_skipped(
    runtime: app.Runtime, alexa: AlexaStandIn
) -> None:
    spoofed = {**load_event("iot_rule_robot_stuck"), "sender": "placebot2"}
    assert app.announce(spoofed, runtime)["told"] == []
    assert app.announce({"event": "stuck", "sender": "placebot1"}, runtime)["told"] == []
    assert alexa.events == []


def test_bad_client_credentials_are_one_line(runtime: app.Runtime, alexa: AlexaStandIn) -> None:
    runtime.alexa._credentials = lambda: (CLIENT_ID, "wrong")
    with pytest.raises(
        DeliveryFailed,
        match=r"^Login with Amazon refused the skill's client credentials \(401: Client authentication failed\)$",
    ):
        app.announce(load_event("iot_rule_robot_stuck"), runtime)


def test_configuration_is_checked_once_in_one_line() -> None:
    with pytest.raises(
        ConfigError,
        match="^VAHR_ANNOUNCER_SECRET, VAHR_ANNOUNCER_TABLE, VAHR_PROACTIVE_EVENTS_URL: not set",
    ):
        AnnouncerConfig.from_env({})
    with pytest.raises(ConfigError, match="^VAHR_ANNOUNCE_SETTINGS: max_per_window"):
        AnnouncerConfig.from_env({"VAHR_ANNOUNCER_SECRET": "s", "VAHR_ANNOUNCER_TABLE": "t",
                                  "VAHR_PROACTIVE_EVENTS_URL": "https://x",
                                  "VAHR_ANNOUNCE_SETTINGS": '{"max_per_window": 0}'})  # fmt: skip
    assert events_url("EU", "live") == "https://api.eu.amazonalexa.com/v1/proactiveEvents/"
    assert events_url("NA", "development") == "https://api.amazonalexa.com" + EVENTS_PATH
