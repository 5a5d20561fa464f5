"""Interpretation by Amazon Lex V2 `RecognizeText`, on the bot generated from
`weather_answers.yaml` (intents `sunny` and `rainy`; anything else is FallbackIntent).

Credentials come from a callable (the IoT credentials provider on a robot), so every call
signs with fresh temporary credentials; boto3 is imported here and nowhere else on the
robot's voice path.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from robot_agent.voice.answers import as_intent
from robot_agent.voice.interpreter import UNKNOWN, Interpretation
from vahr.speech.errors import SpeechError

if TYPE_CHECKING:
    from collections.abc import Callable

    from robot_agent.voice.iot_credentials import TemporaryCredentials

MAX_TEXT_CHARS = 1024  # RecognizeText's limit


class LexInterpreter:
    """One Lex V2 bot alias and locale; one Lex session per robot."""

    def __init__(
        self,
        *,
        bot_id: str,
        bot_alias_id: str,
        locale_id: str = "en_US",
        session_id: str,
        region: str,
        credentials: Callable[[], TemporaryCredentials] | None = None,
        endpoint_url: str | None = None,
        connect_timeout_s: float = 3.0,
        read_timeout_s: float = 5.0,
    ) -> None:
        import boto3
        from botocore.config import Config

        self.bot_id = bot_id
        self.bot_alias_id = bot_alias_id
        self.locale_id = locale_id
        self.session_id = session_id
        self.region = region
        self.endpoint_url = endpoint_url
        self._credentials = credentials
        self._boto3 = boto3
        self._config = Config(
            connect_timeout=connect_timeout_s,
            read_timeout=read_timeout_s,
            retries={"max_attempts": 2, "mode": "standard"},
        )
        self._client: Any = None
        self._client_for: TemporaryCredentials | None = None

    def _lex(self) -> Any:
        if self._credentials is None:
            if self._client is None:
                self._client = self._make_client(self._boto3.Session())
            return self._client
        current = self._credentials()
        if self._client is None or current != self._client_for:
            session = self._boto3.Session(
                aws_access_key_id=current.access_key_id,
                aws_secret_access_key=current.secret_access_key,
                aws_session_token=current.session_token,
            )
            self._client, self._client_for = self._make_client(session), current
        return self._client

    def _make_client(self, session: Any) -> Any:
        return session.client(
            "lexv2-runtime",
            region_name=self.region,
            endpoint_url=self.endpoint_url,
            config=self._config,
        )

    def interpret(self, text: str) -> Interpretation:
        from botocore.exceptions import BotoCoreError, ClientError

        text = text.strip()[:MAX_TEXT_CHARS]
        if not text:
            return UNKNOWN
        try:
            response = self._lex().recognize_text(
                botId=self.bot_id,
                botAliasId=self.bot_alias_id,
                localeId=self.locale_id,
                sessionId=self.session_id,
                text=text,
            )
        except (BotoCoreError, ClientError) as err:
            raise SpeechError(f"Amazon Lex could not interpret the answer: {err}") from err
        intent = response.get("sessionState", {}).get("intent", {}).get("name", "")
        meaning = as_intent(str(intent).lower().removesuffix("intent"))
        if meaning == "unknown":
            return UNKNOWN
        score = 1.0
        for candidate in response.get("interpretations", []):
            if candidate.get("intent", {}).get("name") == intent:
                score = float(candidate.get("nluConfidence", {}).get("score", 1.0))
                break
        return Interpretation(meaning, round(score, 3))
