"""The skill answers in the request's locale: a German request gets German sentences from
the de-DE catalog, an English one the English sentences, and the German catalog has every
message of the English one with the same placeholders."""

from __future__ import annotations

import ast
import string
from pathlib import Path
from typing import Any

import pytest
from skill_testkit import RobotBehaviour, RobotDoubles, reprompt, speech

from skill import catalog, prompts
from tests.conftest import load_event


def _messages() -> dict[str, Any]:
    """The en-US catalog: every upper-case name of skill.prompts that is a message."""
    catalog.use_locale("en-US")
    return {
        name: getattr(prompts, name)
        for name in dir(prompts)
        if name.isupper() and name not in ("INVOCATION_NAME", "WEATHERS")
    }


def _fields(message: Any) -> Any:
    """The placeholders of a message, in its shape (a dict's by key, a tuple's in order)."""
    if isinstance(message, dict):
        return {key: _fields(value) for key, value in message.items()}
    if isinstance(message, (tuple, list)):
        return [_fields(value) for value in message]
    return sorted({field for _, field, _, _ in string.Formatter().parse(message) if field})


def test_every_english_message_has_a_german_translation_with_its_placeholders() -> None:
    german = catalog.replies("de-DE")
    for name, english in _messages().items():
        assert name in german, f"de-DE replies.yaml lacks {name}"
        if name == "ORDINALS":
            assert len(german[name]) == len(english)
            continue
        # The same placeholders; MEMBERS_BUSY's English {verb} ("is"/"are") has no use in
        # the German sentence, which is built so that it needs none.
        expected = _fields(english)
        if name == "MEMBERS_BUSY":
            expected.remove("verb")
        assert _fields(german[name]) == expected, name


def test_the_robots_weather_sentence_stays_english_in_german() -> None:
    # The robots hear the weather with an English recognizer.
    assert catalog.replies("de-DE")["WEATHER"] == {k: v for k, v in _messages()["WEATHER"].items()}


@pytest.mark.usefixtures("aws")
def test_a_german_launch_is_welcomed_in_german_and_an_english_one_in_english(skill: Any) -> None:
    assert speech(skill(load_event("alexa_launch_de"), None)).startswith(
        "Willkommen bei Roboterflotte."
    )
    assert speech(skill(load_event("alexa_launch"), None)).startswith("Welcome to robot fleet.")


def test_a_german_request_leaves_the_next_words_english(skill: Any) -> None:
    # The local stack answers many requests in one thread; what a German one set for
    # itself ends with it
    catalog.use_locale("en-US")
    speech(skill(load_event("alexa_launch_de"), None))
    assert catalog.current_locale() == "en-US"
    assert prompts.WELCOME.startswith("Welcome to robot fleet.")


def test_a_german_command_moves_the_robot_and_is_confirmed_in_german(
    skill: Any, robots: RobotDoubles
) -> None:
    # Given robots that acknowledge, when a German request sends placebot eins to zone a
    response = skill(load_event("alexa_navigate_de"), None)
    # Then the robot got the command and the answer names it in German
    assert [thing for thing, _, _ in robots.answered] == ["placebot1"]
    assert speech(response) == "Placebot eins ist unterwegs Richtung Zone A."


@pytest.mark.usefixtures("aws")
def test_a_locale_without_a_catalog_is_answered_in_english(skill: Any) -> None:
    event = load_event("alexa_launch")
    event["request"]["locale"] = "fr-FR"
    assert speech(skill(event, None)).startswith("Welcome to robot fleet.")


@pytest.mark.usefixtures("aws")
def test_a_german_zone_question_offers_the_spelling_alphabet_in_german(skill: Any) -> None:
    event = load_event("alexa_dialog_zone_ambiguous")
    event["request"]["locale"] = "de-DE"
    response = skill(event, None)
    assert speech(response) == "Zone B oder Zone D?"
    assert reprompt(response) == "Zone B oder Zone D? Du kannst auch bravo oder delta sagen."


def test_the_german_catalog_names_no_message_english_lacks() -> None:
    # A message renamed in English and not in German is spoken in English to Germans.
    english = set(_messages())
    stale = sorted(set(catalog.replies("de-DE")) - english)
    assert stale == []


@pytest.mark.usefixtures("aws")
def test_a_german_request_missing_its_zone_is_asked_in_german(skill: Any) -> None:
    # Given "Schick Roboter zwei" (no zone), in German
    event = load_event("alexa_navigate_missing_zone")
    event["request"]["locale"] = "de-DE"
    response = skill(event, None)
    # Then the question is German, with the zones' German names
    assert speech(response) == ("In welche Zone: Ladezone, Zone A, Zone B, Zone C oder Zone D?")


@pytest.mark.usefixtures("aws")
def test_a_german_fallback_is_answered_in_german(skill: Any) -> None:
    event = load_event("alexa_fallback")
    event["request"]["locale"] = "de-DE"
    assert speech(skill(event, None)).startswith("Tut mir leid, dabei kann Roboterflotte")


def test_a_robot_refusing_a_german_command_is_said_in_german(
    skill: Any, robots: RobotDoubles
) -> None:
    robots.behave("placebot1", RobotBehaviour(result="rejected", reason="busy"))
    response = skill(load_event("alexa_navigate_de"), None)
    assert speech(response) == "Placebot eins hat den Befehl abgelehnt: busy."


def _import_time_reads(tree: ast.Module) -> list[str]:
    """`prompts.NAME` read when a module is imported: at module or class level, or as a
    parameter's default, where it is English whatever the request's locale."""
    found: list[str] = []

    def reads(node: ast.AST) -> list[str]:
        return [
            f"{sub.attr} (line {sub.lineno})"
            for sub in ast.walk(node)
            if isinstance(sub, ast.Attribute)
            and isinstance(sub.value, ast.Name)
            and sub.value.id == "prompts"
        ]

    def visit(body: list[ast.stmt]) -> None:
        for statement in body:
            if isinstance(statement, ast.FunctionDef | ast.AsyncFunctionDef):
                args = statement.args
                for default in [*args.defaults, *(d for d in args.kw_defaults if d)]:
                    found.extend(reads(default))
            elif isinstance(statement, ast.ClassDef):
                visit(statement.body)
            else:
                found.extend(reads(statement))

    visit(tree.body)
    return found


def test_no_message_is_read_before_the_request_says_its_language() -> None:
    skill_dir = Path(prompts.__file__).parent
    early = {
        str(path.relative_to(skill_dir)): reads
        for path in sorted(skill_dir.rglob("*.py"))
        if path.name != "prompts.py"
        and (reads := _import_time_reads(ast.parse(path.read_text(encoding="utf-8"))))
    }
    assert early == {}
