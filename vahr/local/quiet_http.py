"""The HTTP plumbing the lab's servers share (the data plane, the operator station): a
threaded server whose handlers keep connections alive and log at debug level only, served
on a background thread.
"""

from __future__ import annotations

import logging
import sys
import threading
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer

from vahr.errors import VahrError

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


class QuietServer(ThreadingHTTPServer):
    """Each connection on its own daemon thread; `what` names the service in its log."""

    daemon_threads = True
    what = "HTTP"

    def handle_error(self, request: object, client_address: object) -> None:
        # A client closing its kept-alive connection is routine, not a server error.
        if isinstance(sys.exc_info()[1], ConnectionError):
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
