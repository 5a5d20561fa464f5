"""Temporary AWS credentials from the AWS IoT credentials provider, with the robot's
certificate: `GET https://{endpoint}/role-aliases/{alias}/credentials` over mutual TLS.

This is how a robot reaches Amazon Lex without long-lived keys: its IoT certificate
(allowed `iot:AssumeRoleWithCertificate` on the role alias) buys credentials for the role
behind the alias. They are cached until shortly before they expire.
"""

from __future__ import annotations

import json
import ssl
import threading
import urllib.error
import urllib.request
from dataclasses import dataclass
from datetime import UTC, datetime, timedelta
from typing import TYPE_CHECKING
from urllib.parse import quote

from vahr.speech.errors import SpeechError

if TYPE_CHECKING:
    from collections.abc import Callable
    from pathlib import Path

REQUEST_TIMEOUT_S = 5.0
REFRESH_BEFORE = timedelta(minutes=5)


@dataclass(frozen=True)
class TemporaryCredentials:
    access_key_id: str
    secret_access_key: str
    session_token: str
    expiration: datetime


class IotCredentialsProvider:
    """Fetches and caches credentials for one role alias with one robot certificate."""

    def __init__(
        self,
        *,
        endpoint: str,
        role_alias: str,
        thing: str,
        cert: Path,
        key: Path,
        ca: Path | None = None,
        now: Callable[[], datetime] = lambda: datetime.now(UTC),
    ) -> None:
        # `endpoint` is the account's `iot:CredentialProvider` host (optionally host:port).
        self.url = f"https://{endpoint}/role-aliases/{quote(role_alias, safe='')}/credentials"
        self.thing = thing
        self._context = ssl.create_default_context(cafile=str(ca) if ca else None)
        try:
            self._context.load_cert_chain(str(cert), str(key))
        except (OSError, ssl.SSLError) as err:
            raise SpeechError(f"cannot load the robot certificate {cert}: {err}") from err
        self._now = now
        self._cached: TemporaryCredentials | None = None
        self._lock = threading.Lock()

    def get(self) -> TemporaryCredentials:
        with self._lock:
            cached = self._cached
            if cached is None or cached.expiration - REFRESH_BEFORE <= self._now():
                cached = self._cached = self._fetch()
            return cached

    def _fetch(self) -> TemporaryCredentials:
        request = urllib.request.Request(self.url, headers={"x-amzn-iot-thingname": self.thing})
        try:
            with urllib.request.urlopen(
                request, context=self._context, timeout=REQUEST_TIMEOUT_S
            ) as response:
                body = json.loads(response.read())
        except urllib.error.HTTPError as err:
            detail = err.read().decode(errors="replace")[:200]
            raise SpeechError(
                f"the IoT credentials provider refused ({err.code}): {detail or err.reason}"
            ) from err
        except (urllib.error.URLError, OSError, ValueError) as err:
            reason = getattr(err, "reason", err)
            raise SpeechError(f"cannot reach the IoT credentials provider: {reason}") from err
        try:
            found = body["credentials"]
            expiration = datetime.fromisoformat(found["expiration"].replace("Z", "+00:00"))
            return TemporaryCredentials(
                access_key_id=found["accessKeyId"],
                secret_access_key=found["secretAccessKey"],
                session_token=found["sessionToken"],
                expiration=expiration,
            )
        except (KeyError, TypeError, AttributeError, ValueError) as err:
            raise SpeechError(f"the IoT credentials provider's answer lacks {err}") from err
