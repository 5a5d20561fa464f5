"""Fault injection shared by the hardening tests and the long runs in `bench/`.

Each helper does one thing a real failure does (a process killed with SIGKILL, a broker
that crashes and comes back) and waits on a condition with a deadline, never a fixed sleep,
so the same helpers serve a two-minute test and a thirty-minute soak.
"""

from __future__ import annotations

import contextlib
import os
import signal
import socket
import threading
import time
from pathlib import Path
from typing import TYPE_CHECKING

from vahr.twin.recovery import Leftover, started_for

if TYPE_CHECKING:
    from collections.abc import Callable

    from vahr.twin.broker import Mosquitto


def alive(pid: int) -> bool:
    """True while `pid` runs (a zombie waiting to be reaped counts as gone)."""
    try:
        stat = Path(f"/proc/{pid}/stat").read_text()
    except OSError:
        return False
    return stat.rsplit(")", 1)[1].split()[0] != "Z"


def wait_until(condition: Callable[[], bool], timeout_s: float, poll_s: float = 0.02) -> float:
    """Seconds until `condition()` held; raise TimeoutError after `timeout_s`."""
    start = time.monotonic()
    while not condition():
        if time.monotonic() - start > timeout_s:
            raise TimeoutError(f"condition not met within {timeout_s} s")
        time.sleep(poll_s)
    return time.monotonic() - start


def kill_hard(pid: int) -> None:
    """SIGKILL, as the OOM killer or a power cut would; no handler runs."""
    with contextlib.suppress(ProcessLookupError):
        os.kill(pid, signal.SIGKILL)


def wait_all_gone(leftovers: list[Leftover], timeout_s: float) -> float:
    """Seconds until every process in `leftovers` has ended."""
    return wait_until(lambda: not any(alive(p.pid) for p in leftovers), timeout_s)


def processes_of(state_dir: Path) -> list[Leftover]:
    """The running processes started for `state_dir` (mosquitto, robot-agents, ...)."""
    return started_for(state_dir.resolve())


def crash_and_restart_broker(broker: Mosquitto, down_s: float = 0.0) -> float:
    """SIGKILL the broker, keep it down `down_s`, start it again on the same ports and
    persistence; return the seconds from the kill until it accepted connections again."""
    killed_at = time.monotonic()
    broker.kill()
    if down_s:
        time.sleep(down_s)  # the outage itself is what is being simulated
    broker.start()
    return time.monotonic() - killed_at


class TcpProxy:
    """A loopback TCP relay to `target_port` whose connections can be cut at will, as a
    Wi-Fi drop or a NAT timeout cuts them. Clients connect to `port`."""

    def __init__(self, target_port: int) -> None:
        self.target_port = target_port
        self._listener = socket.create_server(("127.0.0.1", 0))
        self.port: int = self._listener.getsockname()[1]
        self._lock = threading.Lock()
        self._pairs: list[tuple[socket.socket, socket.socket]] = []
        self._closed = False
        self.accepted = 0
        self._thread = threading.Thread(target=self._accept, name="fault-proxy", daemon=True)
        self._thread.start()

    def _accept(self) -> None:
        while True:
            try:
                client, _ = self._listener.accept()
            except OSError:
                return  # closed
            try:
                upstream = socket.create_connection(("127.0.0.1", self.target_port), timeout=5)
            except OSError:
                client.close()
                continue
            for sock in (client, upstream):
                sock.settimeout(None)
                sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
            with self._lock:
                self._pairs.append((client, upstream))
                self.accepted += 1
            for source, sink in ((client, upstream), (upstream, client)):
                threading.Thread(target=_pump, args=(source, sink), daemon=True).start()

    def drop_all(self) -> int:
        """Cut every relayed connection at once; return how many were cut.

        `shutdown` rather than a bare `close`: a socket another thread is reading from
        stays open in the kernel until that read returns, so a close alone would cut
        nothing.
        """
        with self._lock:
            pairs, self._pairs = self._pairs, []
        for pair in pairs:
            for sock in pair:
                with contextlib.suppress(OSError):
                    sock.shutdown(socket.SHUT_RDWR)
                sock.close()
        return len(pairs)

    def close(self) -> None:
        self._listener.close()
        self.drop_all()


def _pump(source: socket.socket, sink: socket.socket) -> None:
    try:
        while data := source.recv(65536):
            sink.sendall(data)
    except OSError:
        pass
    finally:
        for sock in (source, sink):
            with contextlib.suppress(OSError):
                sock.shutdown(socket.SHUT_RDWR)


__all__ = [
    "TcpProxy",
    "alive",
    "crash_and_restart_broker",
    "kill_hard",
    "processes_of",
    "wait_all_gone",
    "wait_until",
]
