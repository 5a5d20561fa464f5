"""`free_port` hands out ports a server can bind, outside the range the kernel gives the
local end of outgoing connections, so no client's connection can take one in between."""

from __future__ import annotations

import socket
from pathlib import Path

from vahr.plumbing.ports import LISTEN_PORTS, LOOPBACK, free_port


def test_a_free_port_is_below_the_ephemeral_range_and_can_be_listened_on() -> None:
    ranges = Path("/proc/sys/net/ipv4/ip_local_port_range").read_text(encoding="ascii")
    ephemeral_low = int(ranges.split()[0])
    for _ in range(20):
        port = free_port()
        assert port in LISTEN_PORTS and port < ephemeral_low
        with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as server:
            server.bind((LOOPBACK, port))
            server.listen()


def test_a_port_in_use_is_never_handed_out() -> None:
    taken = []
    try:
        for port in LISTEN_PORTS[:50]:
            sock = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
            try:
                sock.bind((LOOPBACK, port))
            except OSError:
                # Already held, by a server of a test running beside this one.
                sock.close()
                continue
            sock.listen()
            taken.append(sock)
        assert len(taken) > 40
        used = {sock.getsockname()[1] for sock in taken}
        assert not used & {free_port() for _ in range(200)}
    finally:
        for sock in taken:
            sock.close()
