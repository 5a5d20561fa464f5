"""The made-up locale xx-XX of tests/data/locales (invented words: "zub robo un ka plak be"
sends robot one to zone B): its interaction model, generated as a shipped locale's is, and
its understanding data. Small, so a model of it trains in a second or two."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from vahr.assistant.understanding import LanguageUnderstanding, load_understanding
from vahr.domain.fleet import load_fleet
from vahr.domain.locale import Language, read_yaml
from vahr.skill_model.generator import build_interaction_model
from vahr.skill_model.locale_templates import locale_intents

LOCALES = Path(__file__).resolve().parents[1] / "data" / "locales"
LOCALE = "xx-XX"


def made_up_document() -> dict[str, Any]:
    """The locale's interaction model: its templates, its fleet's names, its invocation."""
    language: Language = read_yaml(str(LOCALES / LOCALE / "language.yaml"), Language)
    fleet = load_fleet(LOCALES / LOCALE / "fleet.yaml")
    model = build_interaction_model(fleet, locale_intents(LOCALE, directory=LOCALES))
    model["interactionModel"]["languageModel"]["invocationName"] = language.invocation_name
    return model


def made_up_understanding() -> LanguageUnderstanding:
    return load_understanding(LOCALE, directory=LOCALES)
