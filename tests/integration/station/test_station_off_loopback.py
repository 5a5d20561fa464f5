"""The station served off loopback: its own HTTPS with a certificate from the local CA, or
behind a reverse proxy whose HTTPS origin it is told; the token out of the address after
the first load; a cookie that is Secure under HTTPS and expires; idle connections closed.

Real sockets, real TLS (the client verifies the local CA), and a real headless Chromium.
"""

from __future__ import annotations

import http.client
import json
import socket
import ssl
import time
from typing import TYPE_CHECKING

import pytest
from playwright.sync_api import sync_playwright

from tests.integration.station.test_station_server import TOKEN, make_app
from tests.support.browser import launch
from vahr.pki import LocalCA
from vahr.plumbing.ports import free_port
from vahr.station.server import COOKIE_HOURS, ServerTls, StationServer

if TYPE_CHECKING:
    from collections.abc import Iterator
    from pathlib import Path

    from vahr.domain import Fleet


@pytest.fixture(scope="module")
def ca(tmp_path_factory: pytest.TempPathFactory) -> LocalCA:
    return LocalCA.load_or_create(tmp_path_factory.mktemp("station-ca"))


@pytest.fixture
def https(fleet: Fleet, ca: LocalCA, tmp_path: Path) -> Iterator[StationServer]:
    cert, key = ca.issue_server(["localhost", "127.0.0.1"], tmp_path / "tls")
    with StationServer(
        make_app(fleet), port=free_port(), token=TOKEN, tls=ServerTls(cert, key)
    ) as running:
        yield running


def verified(ca: LocalCA) -> ssl.SSLContext:
    return ssl.create_default_context(cafile=str(ca.ca_file))


def https_request(
    server: StationServer,
    ca: LocalCA,
    method: str,
    path: str,
    body: bytes | None = None,
    headers: dict[str, str] | None = None,
) -> tuple[int, dict[str, str], bytes]:
    connection = http.client.HTTPSConnection(
        "127.0.0.1", server.port, timeout=10, context=verified(ca)
    )
    try:
        connection.request(method, path, body=body, headers=headers or {})
        response = connection.getresponse()
        return response.status, dict(response.getheaders()), response.read()
    finally:
        connection.close()


def test_the_station_serves_https_with_a_certificate_of_the_local_ca(
    https: StationServer, ca: LocalCA
) -> None:
    # Given the station's own TLS, When a client that trusts the local CA (and checks the
    # name) opens the printed address
    assert https.url == f"https://127.0.0.1:{https.port}/?token={TOKEN}"
    status, headers, _ = https_request(https, ca, "GET", f"/?token={TOKEN}")
    # Then the token's cookie is Secure and expires, and the page is opened without it
    assert (status, headers["Location"]) == (303, "/")
    attributes = [part.strip() for part in headers["Set-Cookie"].split(";")]
    assert attributes[0] == f"vahr_station={TOKEN}"
    assert {"Secure", "HttpOnly", "SameSite=Strict", f"Max-Age={COOKIE_HOURS * 3600}"} <= set(
        attributes
    )
    status, _, page = https_request(https, ca, "GET", "/", headers={"Cookie": attributes[0]})
    assert status == 200 and b"<title>VAHR station</title>" in page


def test_a_page_of_another_origin_cannot_post_to_the_https_station(
    https: StationServer, ca: LocalCA
) -> None:
    own = f"https://127.0.0.1:{https.port}"
    auth = {"Authorization": f"Bearer {TOKEN}", "Content-Type": "application/json"}
    # Its own page's origin is served; the plain-HTTP twin of it, or another site, is not
    status, _, _ = https_request(https, ca, "POST", "/api/stop", b"{}", {**auth, "Origin": own})
    assert status != 403
    for origin in (f"http://127.0.0.1:{https.port}", "https://attacker.example"):
        status, _, body = https_request(
            https, ca, "POST", "/api/stop", b"{}", {**auth, "Origin": origin}
        )
        assert (status, json.loads(body)["error"]) == (
            403,
            f"requests from {origin} are not accepted",
        )


def test_plain_http_to_the_https_port_is_refused_and_the_station_keeps_serving(
    https: StationServer, ca: LocalCA
) -> None:
    with socket.create_connection(("127.0.0.1", https.port), timeout=10) as sock:
        sock.sendall(b"GET /api/health HTTP/1.1\r\nHost: 127.0.0.1\r\n\r\n")
        assert b"HTTP/1.1 200" not in sock.recv(4096)
    auth = {"Authorization": f"Bearer {TOKEN}"}
    assert https_request(https, ca, "GET", "/api/health", headers=auth)[0] == 200


def test_behind_a_reverse_proxy_its_https_origin_is_the_pages_own(fleet: Fleet) -> None:
    # Given the station on the lab network behind https://station.lab.example
    public = "https://station.lab.example"
    with StationServer(
        make_app(fleet), host="127.0.0.2", port=free_port(), public_origin=public
    ) as running:
        assert running.token is not None
        assert running.url == f"{public}/?token={running.token}"

        def post(origin: str) -> int:
            # As the proxy forwards it: the public Host and Origin, the browser's cookie
            connection = http.client.HTTPConnection("127.0.0.2", running.port, timeout=10)
            try:
                connection.request(
                    "POST", "/api/stop", body=b"{}",
                    headers={"Host": "station.lab.example", "Origin": origin,
                             "Content-Type": "application/json",
                             "Cookie": f"vahr_station={running.token}"},
                )  # fmt: skip
                return connection.getresponse().status
            finally:
                connection.close()

        # Then the proxy's pages may post, and nothing else
        assert post(public) != 403
        assert post("https://attacker.example") == 403
        assert post("null") == 403
        # And the cookie is Secure: the people's side of the proxy is HTTPS
        assert "; Secure" in running.cookie()
    # Behind a proxy on loopback, the station is reachable by others too: a token guards it
    with StationServer(make_app(fleet), port=free_port(), public_origin=public) as proxied:
        assert proxied.token is not None


def test_an_idle_connection_is_closed_and_frees_its_thread(fleet: Fleet) -> None:
    with StationServer(make_app(fleet), port=free_port(), idle_timeout_s=0.5) as running:
        with socket.create_connection(("127.0.0.1", running.port), timeout=10) as sock:
            started = time.monotonic()
            # Given a client that connects and never finishes its request
            sock.sendall(b"GET /api/health HTTP/1.1\r\n")
            # Then the station closes the connection once it has been idle long enough
            # (the client would otherwise wait out its own 10 s and fail)
            while sock.recv(4096):
                pass
            assert time.monotonic() - started < 5


def test_in_a_browser_the_token_leaves_the_address_and_the_cookie_is_secure(
    https: StationServer,
) -> None:
    with sync_playwright() as playwright:
        browser = launch(playwright)
        try:
            # (Chromium here has no way to trust the test's own CA; the certificate is
            # checked by the tests above.)
            context = browser.new_context(ignore_https_errors=True)
            page = context.new_page()
            page.goto(https.url)
            assert page.url == f"https://127.0.0.1:{https.port}/"
            assert "token" not in page.evaluate("location.href + document.cookie")
            [cookie] = context.cookies()
            assert (cookie["name"], cookie["secure"], cookie["httpOnly"]) == (
                "vahr_station",
                True,
                True,
            )
            assert 0 < cookie["expires"] - time.time() <= COOKIE_HOURS * 3600
            # And the page's own requests, carried by the cookie, are served
            page.wait_for_function("document.title === 'VAHR station'")
            health = page.evaluate("fetch('/api/health').then(r => r.status)")
            assert health == 200
        finally:
            browser.close()
