"""The HTTP plumbing the lab's servers share (the data plane, the operator station): a
threaded server whose handlers keep connections alive, log at debug level only and answer
every request, however mangled, in their own error shape; served on a background thread.
"""

from __future__ import annotations

import logging
import ssl
import sys
import threading
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from typing import TYPE_CHECKING

from vahr.errors import VahrError

if TYPE_CHECKING:
    from collections.abc import Callable

log = logging.getLogger(__name__)


class QuietHandler(BaseHTTPRequestHandler):
    # HTTP/1.1 keeps a client's connection alive between requests (a new TCP connection per
    # call would add a round trip to every shadow read).
    protocol_version = "HTTP/1.1"
    # A response written in two sends (headers, then body) would otherwise wait on Nagle's
    # algorithm for the client's delayed ACK: about 40 ms per request on loopback.
    disable_nagle_algorithm = True

    def log_message(self, format: str, *args: object) -> None:  # noqa: A002
        log.debug("%s " + format, self.address_string(), *args)

    def refuse(self, status: int, message: str) -> None:
        """Answer with an error in the server's own shape (JSON, never http.server's HTML)."""
        raise NotImplementedError

    def unknown_method(self) -> None:
        """A method the handler has no `do_` for (http.server would answer an HTML 501)."""
        self.close_connection = True
        self.refuse(405, f"{self.command} is not used here")

    def __getattr__(self, name: str) -> Callable[[], None]:
        if name.startswith("do_"):
            return self.unknown_method
        raise AttributeError(name)

    def parse_request(self) -> bool:
        if not super().parse_request():
            return False
        if self.request_version == "HTTP/0.9":
            # A request line of two words (a path with a space or line break in it reads
            # so): HTTP/0.9 answers carry no status line, which no client here can read.
            self.send_error(400, "Bad request line: HTTP/1.1 is required")
            return False
        return True

    def send_error(self, code: int, message: str | None = None, explain: str | None = None) -> None:
        """http.server's own rejections (a malformed request line, headers too long, ...)
        in the same shape as every other error."""
        self.close_connection = True
        # The request line may not have been parsed: answer as to a GET of nothing.
        self.command, self.path = self.command or "GET", getattr(self, "path", "") or ""
        # A mangled request line reads as HTTP/0.9, whose answers have no status line;
        # every client of these servers speaks HTTP/1.1, so answer in it.
        self.request_version = "HTTP/1.1"
        self.refuse(code, message or explain or "Bad request")


class QuietServer(ThreadingHTTPServer):
    """Each connection on its own daemon thread; `what` names the service in its log."""

    daemon_threads = True
    what = "HTTP"
    # socketserver's listen backlog is 5: a burst of clients (a station page per operator,
    # a swarm's status questions, a connection flood) overflows it and each refused SYN
    # is retried a second later, which reads as a one-second stall.
    request_queue_size = 128

    def handle_error(self, request: object, client_address: object) -> None:
        # A client closing its kept-alive connection, going quiet, or failing a TLS
        # handshake (a plain-HTTP request to an HTTPS server) is routine, not a server error.
        if isinstance(sys.exc_info()[1], (ConnectionError, TimeoutError, ssl.SSLError)):
            log.debug(
                "%s connection from %s ended: %s", self.what, client_address, sys.exc_info()[1]
            )
            return
        log.exception("%s connection from %s failed", self.what, client_address)


class ServerThread:
    """A `QuietServer` bound at construction (a taken port is one clear error) and served
    on a background thread by `start()`; `stop()` is safe before `start()` and twice."""

    def __init__(
        self, server: type[QuietServer], handler: type[QuietHandler], host: str, port: int
    ) -> None:
        try:
            self.server = server((host, port), handler)
        except OSError as err:
            raise VahrError(f"cannot listen on {host}:{port} for the {server.what}: {err}") from err
        self._thread = threading.Thread(
            target=self.server.serve_forever,
            name=f"vahr-{server.what.replace(' ', '-')}",
            kwargs={"poll_interval": 0.2},
        )
        self._started = False

    @property
    def port(self) -> int:
        port: int = self.server.server_address[1]
        return port

    def start(self) -> None:
        self._thread.start()
        self._started = True

    def stop(self) -> None:
        if self._started:
            self._started = False
            self.server.shutdown()
            self._thread.join(timeout=5)
        self.server.server_close()
