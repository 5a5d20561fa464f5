"""The Lex V2 bot robots use to interpret the assistant's spoken weather answer (optional),
and the IoT role alias through which a robot trades its certificate for credentials that
allow only `lex:RecognizeText` on that bot's alias.

Intents and sample utterances come from `robot_agent/voice/weather_answers.yaml`, the
file the robot's local interpreter reads, so both interpreters know the same answers.
Intent names are the file's keys (`sunny`, `rainy`); anything else is Lex's
`FallbackIntent`, which the robot reads as `unknown`.
"""

from __future__ import annotations

import hashlib
import json
from typing import TYPE_CHECKING

from aws_cdk import aws_iam as iam
from aws_cdk import aws_iot as iot
from aws_cdk import aws_lex as lex
from constructs import Construct

from robot_agent.voice.answers import WeatherAnswers
from vahr.errors import VahrError
from vahr.speech.errors import SpeechError

if TYPE_CHECKING:
    from pathlib import Path

LOCALE = "en_US"
# Below this confidence Lex answers FallbackIntent, and the robot asks again.
CONFIDENCE_THRESHOLD = 0.4
ROLE_ALIAS_CREDENTIAL_SECONDS = 3600


def load_weather_answers(path: Path) -> dict[str, list[str]]:
    """Sample utterances per intent, read by the robot's own reader (lower case, no
    punctuation, unique across intents). Raises VahrError naming what is wrong."""
    try:
        answers = WeatherAnswers.load(path)
    except SpeechError as err:
        raise VahrError(str(err)) from err
    return {intent: list(phrases) for intent, phrases in answers.phrases.items()}


class WeatherBot(Construct):
    """The bot, a version built from its draft, the `alias_name` alias, and the role alias."""

    def __init__(
        self,
        scope: Construct,
        construct_id: str,
        *,
        answers_file: Path,
        bot_name: str,
        alias_name: str,
        role_alias_name: str,
    ) -> None:
        super().__init__(scope, construct_id)
        answers = load_weather_answers(answers_file)
        self.service_role = iam.Role(
            self,
            "ServiceRole",
            assumed_by=iam.ServicePrincipal("lexv2.amazonaws.com"),
            description="Role of the VAHR weather-answer bot (text only: needs no rights)",
        )
        intents = [
            lex.CfnBot.IntentProperty(
                name=intent,
                description=f"The assistant said the weather is {intent}",
                sample_utterances=[
                    lex.CfnBot.SampleUtteranceProperty(utterance=phrase) for phrase in phrases
                ],
            )
            for intent, phrases in answers.items()
        ]
        intents.append(
            lex.CfnBot.IntentProperty(
                name="FallbackIntent",
                description="Anything else: the robot treats it as unknown",
                parent_intent_signature="AMAZON.FallbackIntent",
            )
        )
        self.bot = lex.CfnBot(
            self,
            "Bot",
            name=bot_name,
            description="Interprets the assistant's spoken weather answer for VAHR robots",
            role_arn=self.service_role.role_arn,
            data_privacy={"ChildDirected": False},
            idle_session_ttl_in_seconds=300,
            auto_build_bot_locales=True,
            bot_locales=[
                lex.CfnBot.BotLocaleProperty(
                    locale_id=LOCALE,
                    nlu_confidence_threshold=CONFIDENCE_THRESHOLD,
                    intents=intents,
                )
            ],
        )
        # A bot version is immutable: name it after its content, so a changed answers file
        # makes a new version and moves the alias to it.
        content = hashlib.sha256(json.dumps(answers, sort_keys=True).encode()).hexdigest()[:8]
        self.version = lex.CfnBotVersion(
            self,
            f"Version{content}",
            bot_id=self.bot.attr_id,
            bot_version_locale_specification=[
                lex.CfnBotVersion.BotVersionLocaleSpecificationProperty(
                    locale_id=LOCALE,
                    bot_version_locale_details=lex.CfnBotVersion.BotVersionLocaleDetailsProperty(
                        source_bot_version="DRAFT"
                    ),
                )
            ],
        )
        self.alias = lex.CfnBotAlias(
            self,
            "Alias",
            bot_id=self.bot.attr_id,
            bot_alias_name=alias_name,
            bot_version=self.version.attr_bot_version,
            bot_alias_locale_settings=[
                lex.CfnBotAlias.BotAliasLocaleSettingsItemProperty(
                    locale_id=LOCALE,
                    bot_alias_locale_setting=lex.CfnBotAlias.BotAliasLocaleSettingsProperty(
                        enabled=True
                    ),
                )
            ],
        )
        self.robot_role = iam.Role(
            self,
            "RobotRole",
            assumed_by=iam.ServicePrincipal("credentials.iot.amazonaws.com"),
            description="What a VAHR robot may do with its certificate's temporary credentials",
        )
        self.robot_role.add_to_policy(
            iam.PolicyStatement(actions=["lex:RecognizeText"], resources=[self.alias.attr_arn])
        )
        self.role_alias = iot.CfnRoleAlias(
            self,
            "RoleAlias",
            role_alias=role_alias_name,
            role_arn=self.robot_role.role_arn,
            credential_duration_seconds=ROLE_ALIAS_CREDENTIAL_SECONDS,
        )
        self.role_alias_name = role_alias_name
        self.role_alias_arn: str = self.role_alias.attr_role_alias_arn
        self.bot_id: str = self.bot.attr_id
        self.alias_id: str = self.alias.attr_bot_alias_id
