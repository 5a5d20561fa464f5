"""The Lex V2 bot built from robot_agent/voice/weather_answers.yaml, and the robots' role
alias that allows only lex:RecognizeText on the bot's alias."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import pytest
import yaml
from aws_cdk.assertions import Template
from template_tools import bare_stack, only, resources, role_grants

from infra.config import InfraConfig
from infra.constructs.weather_bot import WeatherBot, load_weather_answers
from vahr.errors import VahrError

if TYPE_CHECKING:
    from pathlib import Path

ANSWERS_FILE = InfraConfig().weather_answers_file


@pytest.fixture(scope="module")
def template(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Any]:
    stack = bare_stack(tmp_path_factory.mktemp("bot"))
    WeatherBot(
        stack,
        "WeatherBot",
        answers_file=ANSWERS_FILE,
        bot_name="vahr-weather-answers",
        alias_name="live",
        role_alias_name="vahr-robot-lex",
    )
    return Template.from_stack(stack).to_json()


def test_the_bot_knows_the_same_answers_as_the_local_interpreter(
    template: dict[str, Any],
) -> None:
    # Given the answers file the robot's local interpreter reads
    source = yaml.safe_load(ANSWERS_FILE.read_text())["intents"]
    # When the bot is synthesized
    [locale] = only(template, "AWS::Lex::Bot")["BotLocales"]
    intents = {intent["Name"]: intent for intent in locale["Intents"]}
    # Then it has one intent per answer kind plus Lex's fallback (the robot's `unknown`)
    assert set(intents) == {"sunny", "rainy", "FallbackIntent"}
    assert intents["FallbackIntent"]["ParentIntentSignature"] == "AMAZON.FallbackIntent"
    # And each intent's utterances are that kind's phrases, lower case, without punctuation
    for kind in ("sunny", "rainy"):
        utterances = [u["Utterance"] for u in intents[kind]["SampleUtterances"]]
        assert len(utterances) == len(set(p.lower() for p in source[kind]))
        assert all(u == u.lower() and "." not in u for u in utterances)
    assert "the weather is sunny" in [u["Utterance"] for u in intents["sunny"]["SampleUtterances"]]
    assert "the weather is rainy" in [u["Utterance"] for u in intents["rainy"]["SampleUtterances"]]
    assert locale["LocaleId"] == "en_US"


def test_the_alias_points_at_a_version_built_from_the_draft(template: dict[str, Any]) -> None:
    [(version_id, version)] = resources(template, "AWS::Lex::BotVersion").items()
    assert version["BotVersionLocaleSpecification"][0]["BotVersionLocaleDetails"] == {
        "SourceBotVersion": "DRAFT"
    }
    alias = only(template, "AWS::Lex::BotAlias")
    assert alias["BotAliasName"] == "live"
    assert alias["BotVersion"] == f"<{version_id}.BotVersion>"


def test_robots_credentials_allow_only_recognize_text_on_the_alias(
    template: dict[str, Any],
) -> None:
    role_alias = only(template, "AWS::IoT::RoleAlias")
    assert role_alias["RoleAlias"] == "vahr-robot-lex"
    role_id = role_alias["RoleArn"].strip("<>").split(".")[0]
    [alias_id] = resources(template, "AWS::Lex::BotAlias")
    assert role_grants(template, role_id) == {("Allow", "lex:RecognizeText", f"<{alias_id}.Arn>")}
    trust = resources(template, "AWS::IAM::Role")[role_id]["AssumeRolePolicyDocument"]
    assert trust["Statement"][0]["Principal"] == {"Service": "credentials.iot.amazonaws.com"}


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("intents: {sunny: [It is sunny.]}", "intents.rainy must be a non-empty list"),
        (
            "intents: {sunny: [Sunny!], rainy: [sunny]}",
            "'sunny' is listed under both sunny and rainy",
        ),
        ("intents: {sunny: [a], rainy: [b], snowy: [c]}", "unknown intents ['snowy']"),
        ("answers: []", "expected a mapping `intents: {sunny: [...], ...}`"),
        ("intents: {sunny: ['...'], rainy: [b]}", "intents.sunny has an empty phrase"),
    ],
)
def test_a_broken_answers_file_is_refused_naming_the_problem(
    tmp_path: Path, text: str, message: str
) -> None:
    answers = tmp_path / "weather_answers.yaml"
    answers.write_text(text)
    with pytest.raises(VahrError, match="^" + str(answers).replace(".", r"\.")) as raised:
        load_weather_answers(answers)
    assert message in str(raised.value)
