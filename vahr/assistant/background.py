"""What the simulator knows beyond the skill's model: Alexa's built-in intents and the world.

Real Alexa trains its built-in intents (help, stop, cancel, ...) and its out-of-domain
detection on Amazon's own data; the skill's model lists those intents without samples. The
simulator stands in for that data with each locale's `built_in` and `out_of_domain`
templates (`understanding.yaml`, read by `vahr.assistant.understanding`): the usual ways
of asking for help or stopping, and everyday requests a voice assistant hears that this
skill does not handle. The out-of-domain phrases train `AMAZON.FallbackIntent`; none of
them is, or is derived from, a sentence of the development set (`vahr nlu --eval`).
"""

from __future__ import annotations

from vahr.assistant.understanding import DEFAULT_LOCALE, LanguageUnderstanding, load_understanding
from vahr.skill_model.templates import expand


def built_in_phrases(
    locale: str = DEFAULT_LOCALE, understanding: LanguageUnderstanding | None = None
) -> dict[str, list[str]]:
    """Each built-in intent's phrases, expanded."""
    data = understanding or load_understanding(locale)
    return {
        intent: [sentence for template in templates for sentence in expand(template)]
        for intent, templates in data.built_in.items()
    }


def out_of_domain_phrases(
    locale: str = DEFAULT_LOCALE, understanding: LanguageUnderstanding | None = None
) -> list[str]:
    """Everyday requests the skill does not handle, expanded."""
    data = understanding or load_understanding(locale)
    return [sentence for template in data.out_of_domain for sentence in expand(template)]
