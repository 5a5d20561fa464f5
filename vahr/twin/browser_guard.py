"""What a web page can make a browser send, refused: the checks in front of the data plane.

The data plane listens on 127.0.0.1 with no credentials, for boto3, the AWS CLI and the
repository's own clients. Any page the operator opens can still reach it through the
browser: a `text/plain` POST in `no-cors` mode is sent without asking first (no preflight),
and a page whose name is rebound to 127.0.0.1 (DNS rebinding) reads the answers as its own.
So a request is served only when:

- its `Host` names this machine's loopback interface (`127.0.0.1`, `localhost`, `::1`) or a
  name the operator configured: a rebound name is not one of them;
- it carries no `Origin` but its own (browsers send one on every POST and on reads a page
  makes with `fetch`), and no `Sec-Fetch-Site` of `cross-site` or `same-site` (a page on
  another port of this machine is the same site, not the same origin);
- a write (any method but GET and HEAD) says it carries JSON or is signed with SigV4: a
  page cannot send either without the browser asking the server first (a CORS preflight,
  which this server never grants). boto3 and the AWS CLI sign every request; the
  repository's own clients send `application/json`.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol
from urllib.parse import urlsplit

LOOPBACK_NAMES = frozenset({"127.0.0.1", "localhost", "::1"})
READS = frozenset({"GET", "HEAD"})
# What `Sec-Fetch-Site` says of a request a page on another origin made.
FOREIGN_FETCH_SITES = frozenset({"cross-site", "same-site"})
# SigV4 (`AWS4-HMAC-SHA256 Credential=...`) and SigV4a (`AWS4-ECDSA-P256-SHA256 ...`).
SIGV4_PREFIX = "AWS4-"


class Headers(Protocol):
    def get(self, name: str, default: None = None) -> str | None: ...


@dataclass(frozen=True)
class Refusal:
    """Why a request is not served: an HTTP status and one line."""

    status: int
    message: str


def host_name(host: str) -> str:
    """The name in a `Host` header, without its port (`[::1]:8180` -> `::1`)."""
    host = host.strip().lower()
    if host.startswith("["):
        return host[1:].split("]", 1)[0]
    return host.rsplit(":", 1)[0] if host.count(":") == 1 else host


def is_json(content_type: str | None) -> bool:
    """`application/json` and AWS's JSON protocols (`application/x-amz-json-1.1`, `+json`)."""
    kind = (content_type or "").split(";", 1)[0].strip().lower()
    return (
        kind == "application/json"
        or kind.startswith("application/x-amz-json")
        or (kind.startswith("application/") and kind.endswith("+json"))
    )


@dataclass(frozen=True)
class BrowserGuard:
    """The checks above, for a server reached through `hosts` as well as through loopback."""

    hosts: frozenset[str] = frozenset()

    def refusal(self, method: str, headers: Headers) -> Refusal | None:
        """None when the request may be served, else why not."""
        host = headers.get("Host") or ""
        if host_name(host) not in LOOPBACK_NAMES | {h.lower() for h in self.hosts}:
            return Refusal(421, f"this server does not answer to the host {host!r}")
        origin = headers.get("Origin")
        if origin is not None and not _same_origin(origin, host):
            return Refusal(403, f"requests from {origin} are not accepted")
        site = (headers.get("Sec-Fetch-Site") or "").strip().lower()
        if site in FOREIGN_FETCH_SITES:
            return Refusal(403, f"requests a page makes from another origin ({site}) are refused")
        if method not in READS and not (
            is_json(headers.get("Content-Type"))
            or (headers.get("Authorization") or "").startswith(SIGV4_PREFIX)
        ):
            return Refusal(415, "a write must send application/json or be signed with AWS SigV4")
        return None


def _same_origin(origin: str, host: str) -> bool:
    try:
        parts = urlsplit(origin.strip())
    except ValueError:
        return False
    return parts.scheme in ("http", "https") and parts.netloc.lower() == host.strip().lower()
