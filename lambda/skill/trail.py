"""The audit trail as the skill writes it: the `Trail` port and where it goes.

- `AuditTable` (`skill.audit_table`): the DynamoDB table the stack makes (AWS);
- `HttpTrail`: the local data plane's `POST {data_endpoint}/vahr/audit` (`vahr up`), which
  numbers and chains the record in its SQLite trail;
- none: the record goes to the log only (a handler built without either).

`audit_trail(config)` picks one, as `skill.task_desk.task_desk` picks the dispatcher. A
record that cannot be written is logged whole at ERROR (`audit_unwritten`), so it is never
lost without a trace, and the reply the person hears is unchanged.
"""

from __future__ import annotations

import logging
import urllib.error
import urllib.request
from typing import TYPE_CHECKING, Protocol

import msgspec

from skill.errors import TrailUnavailable
from skill.logs import log_event
from vahr.protocol import ProtocolError
from vahr.protocol.audit import record_from_json

if TYPE_CHECKING:
    from skill.config import SkillConfig
    from vahr.protocol.audit import AuditEntry, AuditRecord

AUDIT_PATH = "/vahr/audit"
TIMEOUT_S = 2.0


class Trail(Protocol):
    """Where the skill appends a record of each request it acted on."""

    def append(self, entry: AuditEntry) -> AuditRecord | None:
        """Number, chain and store `entry` (the record, where the trail says); raises
        TrailUnavailable when it cannot."""
        ...


class HttpTrail:
    """The local data plane's trail (`POST /vahr/audit`)."""

    def __init__(self, endpoint: str, *, timeout_s: float = TIMEOUT_S) -> None:
        self.url = endpoint.rstrip("/") + AUDIT_PATH
        self.timeout_s = timeout_s

    def append(self, entry: AuditEntry) -> AuditRecord:
        request = urllib.request.Request(  # noqa: S310 - the local data plane, http only
            self.url, data=msgspec.json.encode(entry), method="POST"
        )
        request.add_header("Content-Type", "application/json")
        try:
            with urllib.request.urlopen(request, timeout=self.timeout_s) as response:  # noqa: S310
                return record_from_json(response.read())
        except ProtocolError as err:
            raise TrailUnavailable(f"the trail's answer is no record: {err}") from err
        except urllib.error.HTTPError as err:
            raise TrailUnavailable(f"the trail refused the record: HTTP {err.code}") from err
        except (urllib.error.URLError, OSError) as err:
            raise TrailUnavailable(f"the trail is unreachable: {err}") from err


class LogOnly:
    """No trail: the record is one log line."""

    def append(self, entry: AuditEntry) -> None:
        log_event("audit", record=msgspec.to_builtins(entry))


def audit_trail(config: SkillConfig) -> Trail:
    """The table when the stack names one, else a local data plane's trail, else the log."""
    if config.audit_table:
        from skill.audit_table import AuditTable  # boto3 is imported only when used

        return AuditTable(config.audit_table)
    endpoint = config.data_endpoint
    if endpoint is not None and endpoint.startswith("http://"):
        return HttpTrail(endpoint)
    return LogOnly()


def append_or_log(trail: Trail, entry: AuditEntry) -> None:
    """Append `entry`; when the trail cannot take it, log it whole instead. Nothing the
    trail does changes the reply: the person hears what happened either way."""
    try:
        trail.append(entry)
    except Exception as err:  # noqa: BLE001 - a record must never turn a reply into an error
        log_event(
            "audit_unwritten",
            logging.ERROR,
            error=f"{type(err).__name__}: {err}",
            record=msgspec.to_builtins(entry),
        )
