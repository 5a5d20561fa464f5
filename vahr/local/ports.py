"""Loopback port helpers: find a free port, wait for a listener, name a conflict clearly."""

from __future__ import annotations

import socket
import time

from vahr.errors import VahrError

LOOPBACK = "127.0.0.1"


def free_port() -> int:
    """A TCP port on 127.0.0.1 that nothing listens on right now."""
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as sock:
        sock.bind((LOOPBACK, 0))
        port: int = sock.getsockname()[1]
        return port


def ensure_free(port: int, what: str) -> None:
    """Raise a one-line VahrError if `port` on 127.0.0.1 is already taken."""
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as sock:
        # mosquitto binds with SO_REUSEADDR, so a port left in TIME_WAIT by a killed broker
        # is free for it; the check must agree or a restart would be refused for a minute.
        sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        try:
            sock.bind((LOOPBACK, port))
        except OSError as err:
            raise VahrError(
                f"port {port} for the {what} is already in use on {LOOPBACK}; "
                f"stop what uses it or pick another port"
            ) from err


def wait_for_listener(port: int, timeout_s: float, what: str) -> None:
    """Block until something accepts connections on 127.0.0.1:port, or raise VahrError."""
    deadline = time.monotonic() + timeout_s
    while True:
        try:
            with socket.create_connection((LOOPBACK, port), timeout=0.2):
                return
        except OSError:
            if time.monotonic() > deadline:
                raise VahrError(
                    f"the {what} did not listen on {LOOPBACK}:{port} within {timeout_s:.0f} s"
                ) from None
            time.sleep(0.02)
