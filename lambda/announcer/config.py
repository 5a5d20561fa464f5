"""The announcer's configuration, read once from the environment at cold start.

- `VAHR_ANNOUNCER_SECRET`: the Secrets Manager secret (name or ARN) holding the skill's
  `clientId` and `clientSecret` (developer console, Permissions: Alexa Skill Messaging);
- `VAHR_ANNOUNCER_TABLE`: the DynamoDB table that keeps the policy's state;
- `VAHR_PROACTIVE_EVENTS_URL`: the Proactive Events endpoint of the skill's region and
  stage (`events_url`);
- `VAHR_LWA_TOKEN_URL`: Login with Amazon's token endpoint (default `LWA_TOKEN_URL`);
- `VAHR_IOT_DATA_ENDPOINT`: the iot-data endpoint announcements are published at for the
  operator station (the CDK stack sets the account's; unset: boto3's default);
- `VAHR_ANNOUNCE_SETTINGS`: the policy's settings as JSON (`vahr.announce.AnnounceSettings`);
- `VAHR_LOG_LEVEL`: DEBUG, INFO, WARNING or ERROR (default INFO).
"""

from __future__ import annotations

import os
from typing import TYPE_CHECKING

import msgspec

from announcer.errors import ConfigError
from vahr.announce import AnnounceSettings, settings_from
from vahr.protocol import ProtocolError

if TYPE_CHECKING:
    from collections.abc import Mapping

LWA_TOKEN_URL = "https://api.amazon.com/auth/o2/token"
# Alexa's Proactive Events hosts by the skill's region, and the path of each stage.
REGION_HOSTS = {
    "NA": "https://api.amazonalexa.com",
    "EU": "https://api.eu.amazonalexa.com",
    "FE": "https://api.fe.amazonalexa.com",
}
STAGE_PATHS = {
    "development": "/v1/proactiveEvents/stages/development",
    "live": "/v1/proactiveEvents/",
}


def events_url(region: str, stage: str) -> str:
    """The Proactive Events endpoint for a skill region (NA, EU, FE) and stage."""
    return REGION_HOSTS[region] + STAGE_PATHS[stage]


class AnnouncerConfig(msgspec.Struct, frozen=True, kw_only=True):
    secret: str
    table: str
    events_url: str
    token_url: str = LWA_TOKEN_URL
    iot_data_endpoint: str | None = None
    settings: AnnounceSettings = msgspec.field(default_factory=AnnounceSettings)
    log_level: str = "INFO"

    @classmethod
    def from_env(cls, environ: Mapping[str, str] | None = None) -> AnnouncerConfig:
        env = os.environ if environ is None else environ
        missing = [
            name
            for name in (
                "VAHR_ANNOUNCER_SECRET",
                "VAHR_ANNOUNCER_TABLE",
                "VAHR_PROACTIVE_EVENTS_URL",
            )
            if not env.get(name)
        ]
        if missing:
            raise ConfigError(f"{', '.join(missing)}: not set (the CDK stack sets them)")
        for name in ("VAHR_PROACTIVE_EVENTS_URL", "VAHR_LWA_TOKEN_URL", "VAHR_IOT_DATA_ENDPOINT"):
            url = env.get(name, "https://")
            if not url.startswith(("https://", "http://127.0.0.1")):
                raise ConfigError(f"{name}: {url[:60]!r} must be an https:// URL")
        try:
            settings = settings_from(env.get("VAHR_ANNOUNCE_SETTINGS") or "{}")
        except ProtocolError as err:
            raise ConfigError(f"VAHR_ANNOUNCE_SETTINGS: {err}") from err
        level = (env.get("VAHR_LOG_LEVEL") or "INFO").upper()
        if level not in ("DEBUG", "INFO", "WARNING", "ERROR"):
            raise ConfigError(f"VAHR_LOG_LEVEL: {level!r} must be DEBUG, INFO, WARNING or ERROR")
        return cls(
            secret=env["VAHR_ANNOUNCER_SECRET"],
            table=env["VAHR_ANNOUNCER_TABLE"],
            events_url=env["VAHR_PROACTIVE_EVENTS_URL"],
            token_url=env.get("VAHR_LWA_TOKEN_URL") or LWA_TOKEN_URL,
            iot_data_endpoint=env.get("VAHR_IOT_DATA_ENDPOINT") or None,
            settings=settings,
            log_level=level,
        )
