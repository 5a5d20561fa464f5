"""The station knows its operator: with a users file each person signs in with a token of
their own (the file keeps only its SHA-256), the panel's orders are checked against their
role and recorded in the audit trail with them, a viewer's page has no controls that send
robots, and the page shows the trail.

Real sockets, a real SQLite trail, and real headless Chromium for the pages.
"""

from __future__ import annotations

import http.client
import json
from pathlib import Path
from typing import TYPE_CHECKING, Any

import pytest
from playwright.sync_api import expect, sync_playwright

from tests.support.browser import Watch, launch
from vahr.domain.people import People, token_hash
from vahr.plumbing.ports import free_port
from vahr.protocol import decode_command, topics
from vahr.protocol.audit import verify
from vahr.station.app import StationApp
from vahr.station.controls import Controls
from vahr.station.desk import Desk
from vahr.station.feed import Feed
from vahr.station.server import StationServer
from vahr.station.trail_feed import TrailPoller
from vahr.twin.trail_store import SqliteTrail

if TYPE_CHECKING:
    from collections.abc import Iterator

    from vahr.domain import Fleet

IMAGES = Path(__file__).resolve().parents[3] / "docs" / "images"
TOKENS = {
    "supervisor": "susans-station-token-0123456789",
    "operator": "ottos-station-token-0123456789",
    "viewer": "veras-station-token-0123456789",
}
PEOPLE = People.from_yaml(
    f"""
default_role: viewer
users:
  - {{id: amzn1.ask.account.SUSAN, name: Susan, role: supervisor,
      token_sha256: {token_hash(TOKENS["supervisor"])}}}
  - {{id: amzn1.ask.account.OTTO, name: Otto, role: operator,
      token_sha256: {token_hash(TOKENS["operator"])}}}
  - {{id: amzn1.ask.account.VERA, name: Vera, role: viewer,
      token_sha256: {token_hash(TOKENS["viewer"])}}}
"""
)


class Listening:
    """An assistant that answers every request and keeps who asked (`user`) and from where."""

    def __init__(self) -> None:
        self.asked: list[tuple[str, str, str | None]] = []

    def ask(
        self,
        utterance: str,
        *,
        origin: str = "say",
        heard: dict[str, Any] | None = None,
        user: str | None = None,
    ) -> dict[str, Any]:
        self.asked.append((utterance, origin, user))
        return {"speech": "Placebot one is idle.", "intent": "StatusIntent", "commands": []}


class Station:
    """A station with people and a trail, on a free port; what it published is kept."""

    def __init__(self, fleet: Fleet, state: Path) -> None:
        self.published: list[tuple[str, bytes]] = []
        self.assistant = Listening()
        self.trail = SqliteTrail.in_state_dir(state)
        self.feed = Feed(fleet)
        desk = Desk(self.feed, self._publish)
        app = StationApp(
            feed=self.feed,
            controls=Controls(fleet, desk, self._publish, self.trail.append),
            desk=desk,
            assistant=self.assistant,
            push_to_talk=None,
            synthesize=None,
        )
        self.server = StationServer(app, port=free_port(), people=PEOPLE)
        self.poller = TrailPoller(self.trail, self.feed, every_s=0.2)

    def _publish(self, topic: str, payload: bytes) -> None:
        self.published.append((topic, payload))

    @property
    def url(self) -> str:
        return f"http://127.0.0.1:{self.server.port}"


@pytest.fixture
def station(fleet: Fleet, tmp_path: Path) -> Iterator[Station]:
    running = Station(fleet, tmp_path)
    running.server.start()
    running.poller.start()
    try:
        yield running
    finally:
        running.poller.stop()
        running.server.stop()
        running.trail.close()


def call(
    station: Station, method: str, path: str, body: Any = None, cookie: str | None = None
) -> tuple[int, dict[str, str], Any]:
    connection = http.client.HTTPConnection("127.0.0.1", station.server.port, timeout=10)
    headers = {"Content-Type": "application/json"} if body is not None else {}
    if cookie:
        headers["Cookie"] = f"vahr_station={cookie}"
    try:
        data = json.dumps(body).encode() if body is not None else None
        connection.request(method, path, body=data, headers=headers)
        response = connection.getresponse()
        raw = response.read()
        kind = response.getheader("Content-Type") or ""
        return (
            response.status,
            dict(response.getheaders()),
            json.loads(raw) if "json" in kind else raw,
        )
    finally:
        connection.close()


def test_nothing_but_the_sign_in_page_before_signing_in(station: Station) -> None:
    status, _, page = call(station, "GET", "/")
    assert status == 200 and b"<title>Sign in" in page
    for method, path, body in (
        ("GET", "/api/snapshot", None),
        ("GET", "/api/me", None),
        ("GET", "/api/stream", None),
        ("POST", "/api/stop", {}),
        ("POST", "/api/command", {"robot": "placebot1", "action": "navigate", "zone": "A"}),
    ):
        status, _, answer = call(station, method, path, body)
        assert status == 401, path
        assert answer["error"] == "sign in first: open the station's page and give your token"
    assert station.published == []


def test_a_person_signs_in_with_their_token_and_out_again(station: Station) -> None:
    status, _, answer = call(station, "POST", "/api/signin", {"token": "not-anyones-token"})
    assert (status, answer["error"]) == (401, "That token opens no account at this station.")
    status, headers, answer = call(station, "POST", "/api/signin", {"token": TOKENS["operator"]})
    assert (status, answer) == (200, {"name": "Otto", "role": "operator"})
    cookie = headers["Set-Cookie"]
    assert cookie.startswith(f"vahr_station={TOKENS['operator']}; ") and "HttpOnly" in cookie
    status, _, me = call(station, "GET", "/api/me", cookie=TOKENS["operator"])
    assert me == {
        "id": "amzn1.ask.account.OTTO",
        "name": "Otto",
        "role": "operator",
        "may": ["question", "command", "stop"],
        "signed_in": True,
    }
    status, headers, _ = call(station, "POST", "/api/signout", {}, cookie=TOKENS["operator"])
    assert status == 200 and "Max-Age=0" in headers["Set-Cookie"]


def test_the_token_in_the_address_opens_the_page_once(station: Station) -> None:
    status, headers, _ = call(station, "GET", f"/?token={TOKENS['viewer']}")
    assert (status, headers["Location"]) == (303, "/")
    assert headers["Set-Cookie"].startswith(f"vahr_station={TOKENS['viewer']}; ")
    # A token that opens nothing sets no cookie: the sign-in page shows
    status, headers, _ = call(station, "GET", "/?token=nobodys-token-at-all")
    assert status == 303 and "Set-Cookie" not in headers


def test_each_role_may_use_the_panel_as_it_allows_and_every_order_is_recorded(
    station: Station, fleet: Fleet
) -> None:
    order = {"robot": "placebot1", "action": "navigate", "zone": "B"}
    # The viewer's order is refused and sends nothing; her stop goes
    status, _, answer = call(station, "POST", "/api/command", order, cookie=TOKENS["viewer"])
    assert status == 403
    assert answer["error"] == (
        "Vera is a viewer, who may watch the robots, ask about them and stop them, but not "
        "send them. Nothing was sent."
    )
    assert station.published == []
    status, _, stopped = call(station, "POST", "/api/stop", {}, cookie=TOKENS["viewer"])
    assert status == 200 and station.published[-1][0] == topics.FLEET_CMD
    # The operator's order goes to the robot
    status, _, sent = call(station, "POST", "/api/command", order, cookie=TOKENS["operator"])
    assert status == 200
    topic, payload = station.published[-1]
    assert topic == topics.robot_cmd("placebot1")
    assert decode_command(payload, fleet).params.zone == "B"  # type: ignore[union-attr]
    # And the trail holds all three, with who, the channel and what came of each
    records = station.trail.records()
    assert [(r.name, r.channel, r.outcome, r.robots) for r in records] == [
        ("Vera", "station-panel", "refused", []),
        ("Vera", "station-panel", "sent", ["placebot1", "placebot2"]),
        ("Otto", "station-panel", "sent", ["placebot1"]),
    ]
    assert records[2].commands == [sent["id"]] and records[1].commands == [stopped["id"]]
    assert verify(records, station.trail.head()) == []


def test_what_a_person_types_reaches_the_assistant_as_their_alexa_account(
    station: Station,
) -> None:
    said = {"utterance": "where are the robots", "origin": "station"}
    status, _, turn = call(station, "POST", "/api/say", said, cookie=TOKENS["viewer"])
    assert status == 200 and turn["speech"] == "Placebot one is idle."
    assert station.assistant.asked == [
        ("where are the robots", "station", "amzn1.ask.account.VERA")
    ]


def sign_in(page: Any, station: Station, role: str) -> None:
    page.goto(station.url + "/")
    expect(page.locator("#signin-title")).to_have_text("Sign in")
    page.fill("#signin-token", TOKENS[role])
    page.click("#signin-submit")
    expect(page.locator("#operator-name")).to_be_visible()


def test_in_chromium_an_operator_signs_in_sends_a_robot_and_sees_the_trail(
    station: Station,
) -> None:
    with sync_playwright() as playwright:
        browser = launch(playwright)
        try:
            page = browser.new_page(viewport={"width": 1280, "height": 800})
            watch = Watch(page)
            # A wrong token first: the page says so and stays
            page.goto(station.url + "/")
            page.fill("#signin-token", "somebody-elses-token-000")
            page.click("#signin-submit")
            expect(page.locator("#signin-error")).to_have_text(
                "That token opens no account at this station."
            )
            page.screenshot(path=str(IMAGES / "station-sign-in.png"))
            # Then his own
            page.fill("#signin-token", TOKENS["operator"])
            page.click("#signin-submit")
            expect(page.locator("#operator-name")).to_have_text("Otto · operator")
            expect(page.locator("#zone-row")).to_be_visible()
            # He sends placebot one to zone C with the panel
            page.click("#robot-buttons button[data-thing=placebot1]")
            page.click("#zone-buttons button[data-zone=C]")
            expect(page.locator("#panel-status")).to_contain_text("sent")
            assert station.published[-1][0] == topics.robot_cmd("placebot1")
            # And the trail card shows his order, by name, through the panel
            line = page.locator("#trail-list .trail-line").first
            expect(line.locator(".trail-who")).to_contain_text("Otto")
            expect(line.locator(".trail-channel")).to_have_text("panel")
            expect(line.locator(".trail-outcome")).to_have_text("sent")
            page.screenshot(path=str(IMAGES / "station-operator.png"))
            # The 401 of the first page load before signing in is the only failed request
            assert [p for p in watch.problems if "401" not in p] == []
        finally:
            browser.close()


def test_in_chromium_a_viewers_page_has_no_controls_that_send_robots(station: Station) -> None:
    with sync_playwright() as playwright:
        browser = launch(playwright)
        try:
            page = browser.new_page(viewport={"width": 1280, "height": 800})
            sign_in(page, station, "viewer")
            expect(page.locator("#operator-name")).to_have_text("Vera · viewer")
            expect(page.locator("#zone-row")).to_be_hidden()
            expect(page.locator("#robot-buttons [data-any]")).to_be_hidden()
            expect(page.locator("#panel-role")).to_contain_text("Vera is a viewer")
            # A zone key does nothing; the stop is still hers
            page.click("#robot-buttons button[data-thing=placebot1]")
            page.keyboard.press("c")
            page.wait_for_timeout(300)
            assert station.published == []
            expect(page.locator("#stop-all")).to_be_visible()
            page.click("#stop-all")
            expect(page.locator("#panel-status")).to_have_text("Stop all: sent.")
            assert [topic for topic, _ in station.published] == [topics.FLEET_CMD]
            page.screenshot(path=str(IMAGES / "station-viewer.png"))
            # Signing out returns to the sign-in page
            page.click("#sign-out")
            expect(page.locator("#signin-title")).to_have_text("Sign in")
        finally:
            browser.close()
