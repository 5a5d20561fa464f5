"""The station's HTTP server: the page, its files, the event stream and the API.

It binds 127.0.0.1 unless told otherwise. Bound elsewhere (a tablet on the lab network), it
requires a token, printed at start-up in the station's URL: the first page load carries it
as `?token=`, which sets a cookie for the page's later requests (HttpOnly, SameSite=Strict,
`Secure` when the page is HTTPS, expiring after `COOKIE_HOURS`) and is redirected to the
same page without it, so the token stays in neither the address bar nor the history.

Given the people of a users file (`vahr up --users`, `vahr station --users`), each person
signs in with a token of their own, on loopback too: the file keeps only its SHA-256
(`token_sha256`), `vahr users token` makes one. A page opened without it is the sign-in
page (`static/signin.html`), which posts the token to `POST /api/signin` for the same
cookie; `?token=` in the address works as before, and `POST /api/signout` ends it. Every
request then is that person's: the panel's orders are checked against their role and
recorded with them, and what they type or say reaches the assistant as their Alexa account
(`StationApp`). Off
loopback the page should be HTTPS (browsers give a plain-HTTP page elsewhere no
microphone, and the token would cross the network in the clear): the station serves TLS
itself (`ServerTls`: a certificate from the local CA, or one the user gives), or stands
behind a reverse proxy whose address it is told (`public_origin`), so that the proxy's
HTTPS origin is its own. Every request is checked:

- the `Host` header must name this server (a page elsewhere cannot rebind its own name to
  this address and read the station), and a POST with an `Origin` must come from it (its
  own origin, or the public origin);
- a POST must say what it carries (`application/json`, or `audio/wav` for push-to-talk),
  which a form on another site cannot send without asking first, and must be small:
  `MAX_JSON_BYTES`, or `MAX_AUDIO_BYTES` for a clip (whose length `voice` checks again);
- at most `MAX_STREAMS` pages are streamed to at once, and a connection that sends nothing
  for `IDLE_TIMEOUT_S` is closed, so idle sockets do not hold the server's threads.

The event stream (`GET /api/stream`) is server-sent events: each event is a JSON array of
the feed messages that were waiting (one, or many when robots report faster than the page
reads), with a comment every `KEEPALIVE_S` so a dead connection is noticed. It writes at most
one event a frame (`FRAME_S`): what arrives meanwhile waits, robots' changes merged per
robot, so the page's work per frame stays one parse and one draw however busy the fleet.
"""

from __future__ import annotations

import hmac
import logging
import secrets
import ssl
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass
from http.cookies import CookieError, SimpleCookie
from pathlib import Path
from typing import TYPE_CHECKING
from urllib.parse import parse_qs, urlencode, urlsplit

import msgspec

from vahr.plumbing.http_server import QuietHandler, QuietServer, ServerThread
from vahr.plumbing.ports import LOOPBACK
from vahr.station.app import Reply, error_reply, json_reply
from vahr.station.controls import ANYONE
from vahr.station.floor_picture import MAP_PATH

if TYPE_CHECKING:
    from vahr.domain.people import People, Person
    from vahr.station.app import StationApp

log = logging.getLogger(__name__)

# A route's answer: the handler answers the request at a path, with its query.
Answer = Callable[["_Handler", str, dict[str, str]], None]

STATIC = Path(__file__).with_name("static")
# The page's words per locale (static/i18n.js), served beside its files.
LOCALES = Path(__file__).with_name("locales")
STATIC_PATH = "/static/"
MAX_JSON_BYTES = 16 * 1024
# 16 kHz mono 16-bit is 32 kB a second: a megabyte is half a minute, twice the longest clip.
MAX_AUDIO_BYTES = 1024 * 1024
MAX_STREAMS = 32
KEEPALIVE_S = 15.0
# The least time between two events to a page: one display frame at 60 Hz. The first change
# after a quiet spell goes at once; under load changes are batched a frame at a time.
FRAME_S = 1 / 60
COOKIE = "vahr_station"
# How long the token's cookie opens the station before the URL must be opened again: a day
# of lab work, and not forever on a tablet that leaves the lab.
COOKIE_HOURS = 12
# A connection idle this long (a request never finished, a dead client) is closed; the event
# stream writes a keepalive every KEEPALIVE_S, well inside it.
IDLE_TIMEOUT_S = 30.0
CONTENT_TYPES = {
    ".html": "text/html; charset=utf-8",
    ".css": "text/css; charset=utf-8",
    ".js": "text/javascript; charset=utf-8",
    ".svg": "image/svg+xml",
    ".png": "image/png",
    ".json": "application/json; charset=utf-8",
}
# The page loads only its own files; speech comes back as a blob it plays.
SECURITY_HEADERS = {
    "Content-Security-Policy": (
        "default-src 'self'; script-src 'self'; style-src 'self'; img-src 'self' data:; "
        "media-src 'self' blob:; connect-src 'self'; worker-src 'self'; "
        "frame-ancestors 'none'; base-uri 'none'; form-action 'self'"
    ),
    "X-Content-Type-Options": "nosniff",
    "Referrer-Policy": "no-referrer",
    "Cache-Control": "no-store",
}
LOOPBACK_NAMES = ("127.0.0.1", "localhost", "[::1]")
# What anyone may reach before signing in, where people sign in: the sign-in page and
# its files (the page's code is no secret), and the sign-in itself.
BEFORE_SIGN_IN = frozenset(
    {
        ("GET", "/"),
        ("GET", "/index.html"),
        ("GET", "/favicon.ico"),
        ("GET", "/api/health"),
        ("POST", "/api/signin"),
    }
)
NOT_SIGNED_IN = "sign in first: open the station's page and give your token"
TOKEN_MAX_CHARS = 200


class SignIn(msgspec.Struct, frozen=True):
    """`POST /api/signin`: a person's station token."""

    token: str


def is_loopback(host: str) -> bool:
    return host in ("127.0.0.1", "localhost", "::1")


@dataclass(frozen=True)
class ServerTls:
    """The certificate (chain) and key the station serves HTTPS with."""

    cert_file: Path
    key_file: Path

    def context(self) -> ssl.SSLContext:
        context = ssl.create_default_context(ssl.Purpose.CLIENT_AUTH)
        context.minimum_version = ssl.TLSVersion.TLSv1_2
        context.load_cert_chain(str(self.cert_file), str(self.key_file))
        return context


class _Handler(QuietHandler):
    server: _Server

    def setup(self) -> None:
        super().setup()
        # Every read and write of the connection waits at most this long.
        self.connection.settimeout(self.server.station.idle_timeout_s)

    # -- plumbing -------------------------------------------------------------------------

    def _send(self, reply: Reply, extra: dict[str, str] | None = None) -> None:
        self.send_response(reply.status)
        self.send_header("Content-Type", reply.content_type)
        self.send_header("Content-Length", str(len(reply.body)))
        for name, value in {**SECURITY_HEADERS, **(extra or {})}.items():
            self.send_header(name, value)
        self.end_headers()
        if self.command != "HEAD":
            self.wfile.write(reply.body)

    def refuse(self, status: int, message: str) -> None:
        # A refused request's body may not have been read: close rather than misread it.
        self.close_connection = True
        self._send(error_reply(status, message), {"Connection": "close"})

    def _checked(self) -> tuple[str, dict[str, str]] | None:
        """The path and query of an acceptable request, or None once refused; `operator`
        is then who sent it (None before signing in, on what anyone may reach)."""
        station = self.server.station
        host = self.headers.get("Host", "")
        if not station.host_allowed(host):
            self.refuse(421, f"this station does not answer to the host {host!r}")
            return None
        url = urlsplit(self.path)
        query = {k: v[-1] for k, v in parse_qs(url.query).items()}
        self.operator = self._operator(query)
        if self.operator is None:
            before = (self.command if self.command != "HEAD" else "GET", url.path)
            open_to_all = station.people is not None and (
                before in BEFORE_SIGN_IN or url.path.startswith(STATIC_PATH)
            )
            if not open_to_all:
                if station.people is not None:
                    self.refuse(401, NOT_SIGNED_IN)
                else:
                    self.refuse(401, "this station needs its token: open the URL it printed")
                return None
        origin = self.headers.get("Origin")
        if (
            self.command == "POST"
            and origin is not None
            and not station.origin_allowed(origin, host)
        ):
            self.refuse(403, f"requests from {origin} are not accepted")
            return None
        return url.path, query

    def _offered(self, query: dict[str, str]) -> list[str]:
        """The tokens the request carries: in the address, a bearer header, the cookie."""
        offered = [query.get("token", "")]
        header = self.headers.get("Authorization", "")
        if header.startswith("Bearer "):
            offered.append(header.removeprefix("Bearer "))
        try:
            cookie = SimpleCookie(self.headers.get("Cookie", ""))
            if COOKIE in cookie:
                offered.append(cookie[COOKIE].value)
        except CookieError:
            pass
        return [token for token in offered if token and len(token) <= TOKEN_MAX_CHARS]

    def _operator(self, query: dict[str, str]) -> Person | None:
        """Who sends the request: the person whose token it carries (people sign in), anyone
        as a supervisor (the station's one token, or no token on loopback), or None."""
        station = self.server.station
        if station.people is not None:
            for token in self._offered(query):
                person = station.people.signed_in(token)
                if person is not None:
                    return person
            return None
        if station.token is None:
            return ANYONE
        expected = station.token.encode()
        offered = self._offered(query)
        return ANYONE if any(hmac.compare_digest(expected, o.encode()) for o in offered) else None

    def _body(self, limit: int) -> bytes | None:
        if "chunked" in self.headers.get("Transfer-Encoding", "").lower():
            self.refuse(411, "send the body with a Content-Length, not chunked")
            return None
        try:
            length = int(self.headers.get("Content-Length") or 0)
        except ValueError:
            self.refuse(400, "Content-Length is not a number")
            return None
        if length < 0 or length > limit:
            self.refuse(413, f"the body is {length} bytes; at most {limit} are accepted")
            return None
        return self.rfile.read(length) if length else b""

    # -- the routes -----------------------------------------------------------------------

    def do_GET(self) -> None:  # noqa: N802
        self._route("GET")

    # HEAD is answered as GET; `_send` writes no body for it.
    do_HEAD = do_GET

    def do_POST(self) -> None:  # noqa: N802
        self._route("POST")

    operator: Person | None = None

    def _route(self, method: str) -> None:
        checked = self._checked()
        if checked is None:
            return
        path, query = checked
        answer = self.server.station.route(method, path)
        if answer is not None:
            answer(self, path, query)
        elif method == "POST":
            self.refuse(404, f"nothing to POST at {path}")
        else:
            self._send(error_reply(404, f"nothing at {path}"))

    def _page(self, path: str, query: dict[str, str]) -> None:
        station = self.server.station
        if station.signs_in and query.get("token"):
            # The page's own later requests (the stream, the API) carry the cookie, and the
            # page is opened again without the token in its address (a token that opens
            # nothing sets no cookie: the sign-in page shows).
            rest = urlencode({k: v for k, v in query.items() if k != "token"})
            headers = {"Location": path + (f"?{rest}" if rest else "")}
            if self.operator is not None:
                headers["Set-Cookie"] = station.cookie(query["token"])
            self._send(Reply(303, b"", "text/plain; charset=utf-8"), headers)
            return
        # Nobody signed in: the sign-in page, in the same language.
        page = station.file("index.html" if self.operator is not None else "signin.html")
        # The page shows itself in the language people speak to the assistant unless its
        # reader chose another (static/i18n.js reads `data-locale`).
        body = page.body.replace(
            b'<html lang="en">', f'<html lang="en" data-locale="{station.locale}">'.encode(), 1
        )
        self._send(Reply(page.status, body, page.content_type))

    def _me(self, path: str, query: dict[str, str]) -> None:
        assert self.operator is not None
        self._send(self.server.station.app.me(self.operator))

    def _sign_in(self, path: str, query: dict[str, str]) -> None:
        station = self.server.station
        if self._kind() != "application/json":
            self.refuse(415, "send application/json")
            return
        body = self._body(MAX_JSON_BYTES)
        if body is None:
            return
        try:
            token = msgspec.json.decode(body or b"{}", type=SignIn).token.strip()
        except (msgspec.ValidationError, msgspec.DecodeError):
            self.refuse(400, "token: a string is required")
            return
        person = station.people.signed_in(token) if station.people and token else None
        if person is None:
            log.warning("station: a sign-in with a token that opens no account")
            self._send(error_reply(401, "That token opens no account at this station."))
            return
        log.info("station: %s signed in as %s", person.shown, person.role)
        self._send(
            json_reply({"name": person.name, "role": person.role}),
            {"Set-Cookie": station.cookie(token)},
        )

    def _sign_out(self, path: str, query: dict[str, str]) -> None:
        # The body is read (and ignored), so the connection's next request starts clean.
        if self._body(MAX_JSON_BYTES) is None:
            return
        self._send(json_reply({"signed_out": True}), {"Set-Cookie": self.server.station.cookie("")})

    def _favicon(self, path: str, query: dict[str, str]) -> None:
        self._send(self.server.station.file("favicon.svg"))

    def _static(self, path: str, query: dict[str, str]) -> None:
        self._send(self.server.station.file(path.removeprefix(STATIC_PATH)))

    def _map(self, path: str, query: dict[str, str]) -> None:
        picture = self.server.station.app.feed.picture
        if picture is None:
            self._send(error_reply(404, "this fleet's floor is not a map"))
        else:
            self._send(Reply(200, picture.png, "image/png"))

    def _health(self, path: str, query: dict[str, str]) -> None:
        self._send(json_reply({"ok": True}))

    def _snapshot(self, path: str, query: dict[str, str]) -> None:
        self._send(json_reply(self.server.station.app.feed.snapshot()))

    def _json(self, path: str, query: dict[str, str]) -> None:
        if self._kind() != "application/json":
            self.refuse(415, "send application/json")
            return
        body = self._body(MAX_JSON_BYTES)
        if body is not None:
            assert self.operator is not None
            self._send(self.server.station.app.handle_json("POST", path, body, self.operator))

    def _voice(self, path: str, query: dict[str, str]) -> None:
        if self._kind() not in ("audio/wav", "audio/x-wav", "audio/wave"):
            self.refuse(415, "push-to-talk sends audio/wav")
            return
        body = self._body(MAX_AUDIO_BYTES)
        if body is not None:
            assert self.operator is not None
            self._send(self.server.station.app.voice(body, self.operator))

    def _kind(self) -> str:
        return self.headers.get("Content-Type", "").split(";")[0].strip().lower()

    def _stream(self, path: str, query: dict[str, str]) -> None:
        station = self.server.station
        if not station.open_stream():
            self.refuse(503, f"at most {MAX_STREAMS} pages at once")
            return
        if station.app.push_to_talk is not None:
            # Someone is at the page and may talk: both ears are made now.
            station.app.push_to_talk.warm_up()
        feed = station.app.feed
        subscriber = feed.subscribe()
        self.close_connection = True
        try:
            self.send_response(200)
            self.send_header("Content-Type", "text/event-stream")
            self.send_header("Connection", "close")
            for name, value in SECURITY_HEADERS.items():
                self.send_header(name, value)
            self.end_headers()
            # The browser reconnects a second after a lost stream, and gets a new snapshot.
            self.wfile.write(b"retry: 1000\n\n")
            self.wfile.flush()
            while True:
                messages = subscriber.take(KEEPALIVE_S)
                if messages is None:
                    break
                if messages:
                    # Everything waiting goes as one event (a JSON array): one task for the
                    # page however many robots reported meanwhile.
                    self.wfile.write(b"data: [" + b",".join(messages) + b"]\n\n")
                    self.wfile.flush()
                    time.sleep(FRAME_S)
                else:
                    self.wfile.write(b": keepalive\n\n")
                    self.wfile.flush()
        except OSError:
            pass  # the page went away
        finally:
            feed.unsubscribe(subscriber)
            station.close_stream()


class _Server(QuietServer):
    what = "station"
    station: StationServer


class StationServer:
    """Serve a `StationApp` on host:port in a background thread; `stop()` joins it."""

    def __init__(
        self,
        app: StationApp,
        *,
        host: str = LOOPBACK,
        port: int,
        token: str | None = None,
        tls: ServerTls | None = None,
        public_origin: str | None = None,
        idle_timeout_s: float = IDLE_TIMEOUT_S,
        locale: str = "en-US",
        people: People | None = None,
    ) -> None:
        self.app = app
        # Given, each person signs in with a token of their own (on loopback too).
        self.people = people
        self.host = host
        self.tls = tls
        self.locale = locale
        # Where people open the page when a reverse proxy stands in front (its scheme, name
        # and port): its requests' Origin is this one.
        self.public_origin = public_origin.rstrip("/") if public_origin else None
        self.idle_timeout_s = idle_timeout_s
        # Off the loopback interface, or behind a proxy, the station is reachable by others:
        # a token guards it.
        reachable = not is_loopback(host) or self.public_origin is not None
        if people is not None:
            self.token = None
        else:
            self.token = token or (secrets.token_urlsafe(18) if reachable else None)
        pages = [*STATIC.iterdir(), *LOCALES.iterdir()]
        self._files = {p.name: p for p in pages if p.suffix in CONTENT_TYPES}
        self._streams = 0
        self._streams_lock = threading.Lock()
        # Every route the station answers, by method and path (HEAD is GET); the page's
        # files are the GETs under STATIC_PATH.
        self.routes: dict[tuple[str, str], Answer] = {
            ("GET", "/"): _Handler._page,
            ("GET", "/index.html"): _Handler._page,
            ("GET", "/favicon.ico"): _Handler._favicon,
            ("GET", "/api/health"): _Handler._health,
            ("GET", MAP_PATH): _Handler._map,
            ("GET", "/api/snapshot"): _Handler._snapshot,
            ("GET", "/api/stream"): _Handler._stream,
            ("GET", "/api/me"): _Handler._me,
            ("POST", "/api/voice"): _Handler._voice,
            ("POST", "/api/signin"): _Handler._sign_in,
            ("POST", "/api/signout"): _Handler._sign_out,
            # The JSON API, each route with its body's type (`StationApp.json_routes`).
            **{("POST", path): _Handler._json for path in app.json_routes},
        }
        self._serving = ServerThread(_Server, _Handler, host, port)
        self._serving.server.station = self  # type: ignore[attr-defined]
        if tls is not None:
            # The handshake is made on the connection's own thread, on its first read, so
            # a client slow to shake hands holds no other client back.
            server = self._serving.server
            server.socket = tls.context().wrap_socket(
                server.socket, server_side=True, do_handshake_on_connect=False
            )

    @property
    def port(self) -> int:
        return self._serving.port

    @property
    def scheme(self) -> str:
        return "https" if self.tls is not None else "http"

    @property
    def signs_in(self) -> bool:
        """Whether a page must carry a token: each person's own, or the station's one."""
        return self.people is not None or self.token is not None

    @property
    def secure(self) -> bool:
        """Whether people open the page over HTTPS (here, or at the proxy)."""
        return self.tls is not None or (self.public_origin or "").startswith("https://")

    @property
    def url(self) -> str:
        """The page's address, with the token when one is needed."""
        if self.public_origin is not None:
            base = f"{self.public_origin}/"
        else:
            shown = LOOPBACK if self.host in ("0.0.0.0", "") else self.host  # noqa: S104
            if ":" in shown:
                shown = f"[{shown}]"
            base = f"{self.scheme}://{shown}:{self.port}/"
        return f"{base}?token={self.token}" if self.token else base

    def origin_allowed(self, origin: str, host: str) -> bool:
        """Whether a request with this `Origin` (and `Host`) comes from the station's page."""
        return origin == f"{self.scheme}://{host}" or (
            self.public_origin is not None and origin == self.public_origin
        )

    def cookie(self, token: str | None = None) -> str:
        """The cookie of `token` (the station's own by default; "" ends it): the page's
        later requests carry it, and only they."""
        value = self.token if token is None else token
        assert value is not None
        secure = "; Secure" if self.secure else ""
        age = COOKIE_HOURS * 3600 if value else 0
        return f"{COOKIE}={value}; Path=/; Max-Age={age}; HttpOnly; SameSite=Strict{secure}"

    def route(self, method: str, path: str) -> Answer | None:
        """What answers `method` on `path`, or None (nothing is there)."""
        answer = self.routes.get((method, path))
        if answer is None and method == "GET" and path.startswith(STATIC_PATH):
            return _Handler._static
        return answer

    def host_allowed(self, host: str) -> bool:
        if not is_loopback(self.host) or self.public_origin is not None:
            return True  # reachable by any name on the network; the token decides
        return host in {f"{name}:{self.port}" for name in LOOPBACK_NAMES}

    def file(self, name: str) -> Reply:
        path = self._files.get(name)
        if path is None:
            return error_reply(404, f"no file {name}")
        return Reply(200, path.read_bytes(), CONTENT_TYPES[path.suffix])

    def open_stream(self) -> bool:
        with self._streams_lock:
            if self._streams >= MAX_STREAMS:
                return False
            self._streams += 1
            return True

    def close_stream(self) -> None:
        with self._streams_lock:
            self._streams -= 1

    def start(self) -> StationServer:
        self._serving.start()
        return self

    def stop(self) -> None:
        """Stop serving (safe before `start` and twice)."""
        self.app.feed.close()  # ends every stream, so their threads finish
        self._serving.stop()

    def __enter__(self) -> StationServer:
        return self.start()

    def __exit__(self, *exc: object) -> None:
        self.stop()
