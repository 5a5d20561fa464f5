"""What the audit trail costs on one machine: an append to the SQLite trail, the same append
as the skill makes it (`POST /vahr/audit` on the data plane), and `vahr audit --verify`'s
work on a long trail.

    .venv/bin/python bench/audit_trail.py [--appends 2000] [--records 10000]

Every request the skill acts on appends one record, so the HTTP append is what a command
pays for its record; the verification reads every record and recomputes every hash.
"""

from __future__ import annotations

import argparse
import tempfile
import time
from pathlib import Path

from _results import median, percentile, write_section

from skill.trail import HttpTrail
from vahr.protocol.audit import AuditEntry, now, verify
from vahr.twin.dataplane import DataPlane, DataPlaneServer
from vahr.twin.meter import Meter
from vahr.twin.shadow_service import ShadowService
from vahr.twin.shadow_store import ShadowStore
from vahr.twin.trail_store import AUDIT_PATH, SqliteTrail, TrailApi


def entry(number: int) -> AuditEntry:
    """A record as a confirmed fleet command makes one (about 600 bytes of JSON)."""
    return AuditEntry(
        time=now(),
        who="amzn1.ask.account.AF3QEXAMPLEEXAMPLEEXAMPLEEXAMPLE",
        name="Dr. Weber",
        role="supervisor",
        channel="alexa",
        words="send all robots to zone a",
        intent="NavigateIntent",
        slots={"robot": "all", "zone": "A"},
        robots=["placebot1", "placebot2"],
        commands=[f"{number:032x}"],
        outcome="confirmed",
    )


def milliseconds(samples: list[float]) -> tuple[float, float]:
    return median(samples) * 1000, percentile(samples, 95) * 1000


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--appends", type=int, default=2000)
    parser.add_argument("--records", type=int, default=10_000)
    args = parser.parse_args()
    with tempfile.TemporaryDirectory(prefix="vahr-bench-trail-") as state:
        trail = SqliteTrail.in_state_dir(Path(state) / "direct")
        direct = []
        for number in range(args.appends):
            started = time.perf_counter()
            trail.append(entry(number))
            direct.append(time.perf_counter() - started)
        trail.close()

        served = SqliteTrail.in_state_dir(Path(state) / "served")
        store = ShadowStore(None)
        dataplane = DataPlane(ShadowService(store, lambda *_: None), lambda *_: None, Meter())
        api = TrailApi(served)
        dataplane.local_routes[("POST", AUDIT_PATH)] = api.append
        server = DataPlaneServer(dataplane, 0).start()
        try:
            client = HttpTrail(server.url)
            over_http = []
            for number in range(args.appends):
                started = time.perf_counter()
                client.append(entry(number))
                over_http.append(time.perf_counter() - started)
        finally:
            server.stop()
            served.close()
            store.close()

        long = SqliteTrail.in_state_dir(Path(state) / "long")
        for number in range(args.records):
            long.append(entry(number))
        started = time.perf_counter()
        records, head = long.snapshot(0, args.records)
        read_s = time.perf_counter() - started
        started = time.perf_counter()
        faults = verify(records, head)
        verify_s = time.perf_counter() - started
        long.close()
        assert not faults, faults

    direct_ms, http_ms = milliseconds(direct), milliseconds(over_http)
    body = (
        f"{args.appends:,} appends each way, one record about 600 bytes of JSON; a trail of "
        f"{args.records:,} records verified.\n\n"
        "| what | median ms | p95 ms |\n| --- | ---: | ---: |\n"
        f"| append to the SQLite trail (one `BEGIN IMMEDIATE` transaction) "
        f"| {direct_ms[0]:.2f} | {direct_ms[1]:.2f} |\n"
        f"| append as the skill makes it (`POST /vahr/audit` on the data plane) "
        f"| {http_ms[0]:.2f} | {http_ms[1]:.2f} |\n\n"
        f"`vahr audit --verify` of {args.records:,} records: read {read_s * 1000:.0f} ms, "
        f"verify {verify_s * 1000:.0f} ms ({verify_s / args.records * 1e6:.0f} µs a record).\n"
        "The record is written after the reply is decided and before it is sent, so a command "
        "pays the HTTP append once; Alexa allows 8 s."
    )
    write_section("audit_trail", "Audit trail: appending and verifying", body)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
