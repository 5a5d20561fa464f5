"""Loopback port helpers: find a free port, wait for a listener, name a conflict clearly."""

from __future__ import annotations

import random
import socket
import time

from vahr.errors import VahrError

LOOPBACK = "127.0.0.1"
# Where `free_port` picks from: below the kernel's ephemeral range (32768-60999 on Linux,
# 49152-65535 elsewhere), which is where a port the kernel chose for `bind(0)` comes from,
# and also the local end of every outgoing connection. A port picked there could be taken
# by some client's connection before the server it was picked for binds it (seen in CI:
# "cannot listen on 127.0.0.1:60573 for the station: Address already in use").
LISTEN_PORTS = range(20_000, 32_768)


def free_port() -> int:
    """A TCP port on 127.0.0.1 that nothing listens on right now, outside the range the
    kernel gives outgoing connections (`LISTEN_PORTS`)."""
    for _ in range(200):
        port = random.choice(LISTEN_PORTS)  # noqa: S311 - a port, not a secret
        with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as sock:
            try:
                sock.bind((LOOPBACK, port))
            except OSError:
                continue
            return port
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as sock:
        sock.bind((LOOPBACK, 0))  # that range is full: any port the kernel gives
        chosen: int = sock.getsockname()[1]
        return chosen


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
