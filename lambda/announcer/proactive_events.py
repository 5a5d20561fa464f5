"""The Alexa Proactive Events API adapter: an announcement in, a 202 Accepted out.

Request and retries as Amazon documents them (docs/deploy.md, "Announcements"):

- a token from Login with Amazon (`grant_type=client_credentials`, the skill's client id
  and secret, `scope=alexa::proactive_events`), kept until shortly before it expires;
- `POST` the event to the region's and stage's endpoint with `Authorization: Bearer`;
  202 means accepted;
- 401 (the token expired or was revoked): a new token, once; 409 (this `referenceId` was
  already sent, e.g. by an earlier attempt of this same event): delivered; 429 (too many
  requests) and 5xx: wait (`Retry-After` when given, else exponential back-off with
  jitter) and try again, up to `max_attempts`; 400 and 403 are not helped by retrying.

Every failure is logged with the status and the API's own message, and raised as
`DeliveryFailed`. urllib is the only HTTP library here (nothing to bundle).
"""

from __future__ import annotations

import json
import logging
import random
import time
import urllib.error
import urllib.parse
import urllib.request
from datetime import timedelta
from typing import TYPE_CHECKING, Any

from announcer.errors import DeliveryFailed

if TYPE_CHECKING:
    from collections.abc import Callable

    from vahr.protocol.announcements import Announcement

log = logging.getLogger("announcer")

SCOPE = "alexa::proactive_events"
EVENT_NAME = "AMAZON.MessageAlert.Activated"
# Alexa deletes a notification nobody heard after this (it allows 5 minutes to 24 hours).
EXPIRY = timedelta(hours=1)
TIMEOUT_S = 5.0
MAX_ATTEMPTS = 3
BACKOFF_S = 0.5
MAX_WAIT_S = 4.0
TOKEN_MARGIN_S = 60.0


def event_body(announcement: Announcement, *, creator: str, urgent: bool) -> dict[str, Any]:
    """The Proactive Events request for one announcement (AMAZON.MessageAlert.Activated:
    Alexa says "you have a new urgent message from placebot one")."""
    group: dict[str, Any] = {"creator": {"name": creator}, "count": 1}
    if urgent:
        group["urgency"] = "URGENT"
    audience: dict[str, Any] = (
        {"type": "Multicast", "payload": {}}
        if announcement.person == "everyone"
        else {"type": "Unicast", "payload": {"user": announcement.person}}
    )
    return {
        "timestamp": _rfc3339(announcement.time),
        "referenceId": announcement.id,
        "expiryTime": _rfc3339(announcement.time + EXPIRY),
        "event": {
            "name": EVENT_NAME,
            "payload": {
                "state": {
                    "status": "UNREAD",
                    "freshness": "OVERDUE" if announcement.kind == "waiting" else "NEW",
                },
                "messageGroup": group,
            },
        },
        "localizedAttributes": [],
        "relevantAudience": audience,
    }


def _rfc3339(moment: Any) -> str:
    return moment.strftime("%Y-%m-%dT%H:%M:%S.") + f"{moment.microsecond // 1000:03d}Z"


class ProactiveEvents:
    """Send announcements; `credentials()` gives the skill's (client id, client secret)."""

    def __init__(
        self,
        *,
        token_url: str,
        events_url: str,
        credentials: Callable[[], tuple[str, str]],
        sleep: Callable[[float], None] = time.sleep,
        clock: Callable[[], float] = time.monotonic,
        max_attempts: int = MAX_ATTEMPTS,
    ) -> None:
        self._token_url = token_url
        self._events_url = events_url
        self._credentials = credentials
        self._sleep = sleep
        self._clock = clock
        self._max_attempts = max_attempts
        self._token: tuple[str, float] | None = None

    def send(self, announcement: Announcement, *, creator: str, urgent: bool) -> str:
        """Deliver one announcement: "accepted", or "duplicate" (already delivered)."""
        body = json.dumps(event_body(announcement, creator=creator, urgent=urgent)).encode()
        refreshed = False
        for attempt in range(1, self._max_attempts + 1):
            status, reason, retry_after = self._post(body, self._access_token())
            if status == 202:
                return "accepted"
            if status == 409:
                log.info("announcement %s was already delivered (409: %s)", announcement.id, reason)
                return "duplicate"
            log.warning(
                "Proactive Events answered %s for %s (attempt %d of %d): %s",
                status, announcement.id, attempt, self._max_attempts, reason,
            )  # fmt: skip
            if status == 401 and not refreshed:
                self._token, refreshed = None, True  # expired or revoked: a new one, once
                continue
            if status in (400, 401, 403):
                raise DeliveryFailed(
                    f"Alexa refused announcement {announcement.id} ({status}: {reason})",
                    status=status,
                    retryable=False,
                )
            if attempt < self._max_attempts:
                self._sleep(self._backoff(attempt, retry_after))
        raise DeliveryFailed(
            f"Alexa did not accept announcement {announcement.id} after "
            f"{self._max_attempts} attempts ({status}: {reason})",
            status=status,
        )

    def _backoff(self, attempt: int, retry_after: float | None) -> float:
        if retry_after is not None:
            return min(retry_after, MAX_WAIT_S)
        return min(MAX_WAIT_S, BACKOFF_S * 2 ** (attempt - 1)) * random.uniform(0.5, 1.0)

    def _access_token(self) -> str:
        if self._token is not None and self._clock() < self._token[1]:
            return self._token[0]
        client_id, client_secret = self._credentials()
        form = urllib.parse.urlencode(
            {
                "grant_type": "client_credentials",
                "client_id": client_id,
                "client_secret": client_secret,
                "scope": SCOPE,
            }
        ).encode()
        request = urllib.request.Request(
            self._token_url,
            data=form,
            method="POST",
            headers={"Content-Type": "application/x-www-form-urlencoded;charset=UTF-8"},
        )
        status, answer, _ = _exchange(request)
        if status != 200:
            raise DeliveryFailed(
                f"Login with Amazon refused the skill's client credentials ({status}: "
                f"{_reason(answer)})",
                status=status,
                retryable=status == 429 or status >= 500,
            )
        try:
            token = json.loads(answer)
            access, lifetime = str(token["access_token"]), float(token.get("expires_in", 3600))
        except (ValueError, KeyError, TypeError) as err:
            raise DeliveryFailed(f"Login with Amazon answered no token ({err})") from err
        self._token = (access, self._clock() + max(0.0, lifetime - TOKEN_MARGIN_S))
        return access

    def _post(self, body: bytes, token: str) -> tuple[int, str, float | None]:
        request = urllib.request.Request(
            self._events_url,
            data=body,
            method="POST",
            headers={"Content-Type": "application/json", "Authorization": f"Bearer {token}"},
        )
        status, answer, headers = _exchange(request)
        retry_after = headers.get("Retry-After")
        try:
            wait = float(retry_after) if retry_after is not None else None
        except ValueError:
            wait = None
        return status, _reason(answer), wait


def _exchange(request: urllib.request.Request) -> tuple[int, bytes, dict[str, str]]:
    """(status, body, headers); a network failure is a retryable DeliveryFailed."""
    try:
        with urllib.request.urlopen(request, timeout=TIMEOUT_S) as response:  # noqa: S310
            return response.status, response.read(), dict(response.headers)
    except urllib.error.HTTPError as err:
        return err.code, err.read(), dict(err.headers or {})
    except (urllib.error.URLError, TimeoutError, ConnectionError) as err:
        reason = getattr(err, "reason", err)
        raise DeliveryFailed(f"cannot reach {request.full_url} ({reason})") from err


def _reason(answer: bytes) -> str:
    """The API's own message (`{"code", "message"}`, or LWA's `error_description`)."""
    try:
        parsed = json.loads(answer or b"{}")
    except ValueError:
        return answer[:120].decode(errors="replace") or "no message"
    if isinstance(parsed, dict):
        for key in ("message", "error_description", "error"):
            if isinstance(parsed.get(key), str):
                return str(parsed[key])[:200]
    return "no message"
