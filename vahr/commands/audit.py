"""`vahr audit`: print the audit trail, or verify that nobody changed it.

Reads a running `vahr up` (`GET {api}/vahr/audit`, page by page), the trail a stopped one
left (`--state-dir`), or the DynamoDB table on AWS (`--table`). `--verify` recomputes every
record's hash and the chain itself (it trusts no server's word), prints what it found and
exits 1 when the trail was altered.
"""

from __future__ import annotations

import csv
import json
import sys
from pathlib import Path
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    import argparse

    from vahr.protocol.audit import AuditRecord, TrailHead

PAGE = 1000


def configure(parser: argparse.ArgumentParser) -> None:
    source = parser.add_mutually_exclusive_group()
    source.add_argument("--api", help="the running system's API (default $VAHR_API or :8180)")
    source.add_argument(
        "--state-dir",
        type=Path,
        help="read the trail a vahr up left in this state directory (it need not be running)",
    )
    source.add_argument("--table", help="the DynamoDB audit table of a deployment on AWS")
    shape = parser.add_mutually_exclusive_group()
    shape.add_argument("--json", action="store_true", help="print the records as a JSON array")
    shape.add_argument("--csv", action="store_true", help="print the records as CSV")
    parser.add_argument(
        "--verify",
        action="store_true",
        help="check every record's hash and the chain; exit 1 when the trail was altered",
    )
    parser.add_argument("--last", type=int, metavar="N", help="print only the last N records")


def run(args: argparse.Namespace) -> int:
    from vahr.errors import VahrError

    if args.last is not None and args.last < 1:
        raise VahrError("--last: give 1 or more records")
    records, head = _read(args)
    if args.verify:
        return _verify(records, head, as_json=args.json)
    shown = records[-args.last :] if args.last else records
    if args.json:
        import msgspec

        print(msgspec.json.encode(shown).decode())
    elif args.csv:
        _write_csv(shown)
    else:
        for record in shown:
            print(_line(record))
        if not shown:
            print("The audit trail is empty.")
    return 0


def _read(args: argparse.Namespace) -> tuple[list[AuditRecord], TrailHead | None]:
    from vahr.errors import VahrError

    if args.table:
        from skill.audit_table import AuditTable
        from skill.errors import GatewayError

        table = AuditTable(args.table)
        try:
            return table.records(), table.head()
        except GatewayError as err:
            raise VahrError(str(err)) from err
    if args.state_dir is not None:
        from vahr.twin.trail_store import FILE_NAME, SqliteTrail

        file = args.state_dir / FILE_NAME
        if not file.is_file():
            raise VahrError(f"{file}: no audit trail here (vahr up --state-dir keeps it)")
        trail = SqliteTrail(file)
        try:
            records, head = trail.snapshot(0, sys.maxsize)
        finally:
            trail.close()
        return records, head
    return _read_api(args.api)


def _read_api(api: str | None) -> tuple[list[AuditRecord], TrailHead | None]:
    from vahr.errors import VahrError
    from vahr.plumbing.client import call, default_api
    from vahr.protocol import ProtocolError
    from vahr.protocol.audit import TrailHead, record_from_builtins

    url = api or default_api()
    records: list[AuditRecord] = []
    head: TrailHead | None = None
    after = 0
    while True:
        page = call(url, "GET", f"/vahr/audit?after={after}&limit={PAGE}")
        try:
            records += [record_from_builtins(item) for item in page.get("records", [])]
        except ProtocolError as err:
            raise VahrError(f"{url}/vahr/audit answered a record that is none: {err}") from err
        found = page.get("head")
        head = TrailHead(int(found["seq"]), str(found["hash"])) if found else None
        if page.get("next") is None:
            return records, head
        after = int(page["next"])


def _verify(records: list[AuditRecord], head: TrailHead | None, *, as_json: bool) -> int:
    from vahr.protocol.audit import verify

    faults = verify(records, head)
    if as_json:
        print(
            json.dumps(
                {
                    "intact": not faults,
                    "records": len(records),
                    "head": {"seq": head.seq, "hash": head.hash} if head else None,
                    "faults": [{"seq": f.seq, "reason": f.reason} for f in faults],
                }
            )
        )
        return 1 if faults else 0
    for fault in faults:
        print(f"altered: {fault}")
    if faults:
        print(f"The audit trail was altered: {len(faults)} fault(s) in {len(records)} records.")
        return 1
    ending = f"; its head is record {head.seq}, hash {head.hash}" if head else ""
    count = f"{len(records)} record{'' if len(records) == 1 else 's'}"
    print(f"The audit trail is intact: {count}{ending}.")
    return 0


def _write_csv(records: list[AuditRecord]) -> None:
    from vahr.protocol.audit import CSV_COLUMNS

    writer = csv.writer(sys.stdout, lineterminator="\n")
    writer.writerow(CSV_COLUMNS)
    for record in records:
        writer.writerow([_cell(getattr(record, column)) for column in CSV_COLUMNS])


def _cell(value: Any) -> str:
    if value is None:
        return ""
    if isinstance(value, dict):
        return json.dumps(value, sort_keys=True, ensure_ascii=False)
    if isinstance(value, list):
        return " ".join(str(item) for item in value)
    return str(value)


def _line(record: AuditRecord) -> str:
    who = record.name or record.who
    role = f" ({record.role})" if record.role else ""
    robots = f" -> {', '.join(record.robots)}" if record.robots else ""
    said = f' "{record.words}"' if record.words else ""
    reason = f" [{record.reason}]" if record.reason else ""
    return (
        f"{record.seq:>5} {record.time} {record.channel:<14} {who}{role}: "
        f"{record.intent or '-'} {record.outcome}{robots}{said}{reason}"
    )
