"""Where the handler learns the skill id it serves: its configuration, or an SSM parameter.

A stack that creates the skill itself (`cdk deploy -c skill=true`) cannot give the function
the skill's id in its environment: the function must exist, and Alexa be allowed to call
it, before the skill and its id do. The stack then writes the id into an SSM parameter once
the skill exists, and names the parameter in `VAHR_SKILL_ID_PARAMETER`; the handler reads
it on its first request (boto3's `ssm` client, imported only here). Until the read
succeeds the handler has no skill id and, on Lambda, refuses every request (skill.skill_gate);
a failed read is tried again on the next request and logged, never cached.
"""

from __future__ import annotations

import logging
import threading
from typing import Any

from skill.logs import log_event

# The parameter is read once per Lambda instance; these bound that first request's wait.
TIMEOUT_S = 1.0


class SkillIdSource:
    """The configured skill id, or the parameter's value once read."""

    def __init__(self, skill_id: str | None, parameter: str | None, client: Any = None) -> None:
        self._skill_id = skill_id
        self._parameter = parameter if skill_id is None else None
        self._client = client
        self._lock = threading.Lock()

    def __call__(self) -> str | None:
        if self._skill_id is not None or self._parameter is None:
            return self._skill_id
        with self._lock:
            if self._skill_id is None:
                self._skill_id = self._read(self._parameter)
        return self._skill_id

    def _read(self, parameter: str) -> str | None:
        import boto3
        from botocore.config import Config
        from botocore.exceptions import BotoCoreError, ClientError

        try:
            if self._client is None:
                self._client = boto3.client(
                    "ssm",
                    config=Config(
                        connect_timeout=TIMEOUT_S,
                        read_timeout=TIMEOUT_S,
                        retries={"mode": "standard", "total_max_attempts": 2},
                    ),
                )
            value = self._client.get_parameter(Name=parameter)["Parameter"]["Value"]
        except (BotoCoreError, ClientError, KeyError) as err:
            log_event(
                "skill_id_unavailable", logging.ERROR, parameter=parameter, error=str(err)[:300]
            )
            return None
        return value if isinstance(value, str) and value.strip() else None
