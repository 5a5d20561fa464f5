"""The skill manifest (`skill-package/skill.json`) as data.

The Lambda endpoint is not generated: `python -m infra.skill_endpoint` writes the deployed
function's ARN into skill.json for `ask deploy`, and the CDK stack passes it to `CfnSkill`
as an override. The generator keeps an endpoint it finds in the existing skill.json, so
regenerating after a deployment does not undo it.
"""

from __future__ import annotations

from typing import Any

from vahr.domain.invocation import INVOCATION_NAME
from vahr.domain.locale import load_language
from vahr.skill_model.intents import LOCALE

SKILL_NAME = "VAHR Robot Fleet"
# The announcer function (lambda/announcer) sends Alexa notifications of robots' troubles:
# the skill asks for the notifications permission and declares the one event schema it
# publishes.
NOTIFICATIONS_PERMISSION = "alexa::devices:all:notifications:write"
PUBLISHED_EVENTS = ("AMAZON.MessageAlert.Activated",)


GERMAN = "de-DE"


def german_publishing() -> dict[str, Any]:
    """The skill's store entry in German: what the German templates let people say."""
    name = load_language(GERMAN).invocation_name
    return {
        "name": "VAHR Roboterflotte",
        "summary": "Steuere eine Flotte von Lagerrobotern mit der Stimme.",
        "description": (
            "Schicke Roboter in Zonen, lass sie Pakete liefern (auch je nach Wetter oder "
            "nacheinander), frag, wo sie sind, und halte sie sofort an. Die Befehle laufen "
            "über AWS IoT Core; der Skill bestätigt, dass jeder Roboter sie angenommen hat."
        ),
        "examplePhrases": [
            f"Alexa, öffne {name}",
            f"Alexa, sage {name}, schicke placebot eins in zone a",
            f"Alexa, frage {name}, wo sind die roboter",
        ],
        "keywords": ["roboter", "flotte", "lager", "lieferung", "forschung"],
    }


def build_manifest(endpoint: dict[str, Any] | None = None) -> dict[str, Any]:
    """The ASK CLI v2 `skill.json` for the custom skill, with `endpoint` if one is deployed."""
    custom: dict[str, Any] = {"interfaces": []}
    if endpoint is not None:
        custom["endpoint"] = endpoint
    return {
        "manifest": {
            "manifestVersion": "1.0",
            "publishingInformation": {
                "locales": {
                    LOCALE: {
                        "name": SKILL_NAME,
                        "summary": "Command a fleet of warehouse robots by voice.",
                        "description": (
                            "Send robots to zones, have them deliver packages (also based on "
                            "the weather, or one after the other), ask where they are, and "
                            "stop them at once. Commands travel through AWS IoT Core; the "
                            "skill confirms that each robot acknowledged them."
                        ),
                        "examplePhrases": [
                            f"Alexa, open {INVOCATION_NAME}",
                            f"Alexa, ask {INVOCATION_NAME} to send placebot one to zone a",
                            f"Alexa, ask {INVOCATION_NAME} where are the robots",
                        ],
                        "keywords": ["robots", "fleet", "warehouse", "delivery", "research"],
                    },
                    GERMAN: german_publishing(),
                },
                "isAvailableWorldwide": False,
                "distributionCountries": ["US", "DE"],
                "testingInstructions": (
                    "Run the robots (robot-agent) or the local stack (vahr up), then say "
                    "'send placebot one to zone a' and 'where are the robots'."
                ),
                "category": "PRODUCTIVITY",
            },
            "apis": {"custom": custom},
            "permissions": [{"name": NOTIFICATIONS_PERMISSION}],
            "events": {"publications": [{"eventName": name} for name in PUBLISHED_EVENTS]},
            "privacyAndCompliance": {
                "allowsPurchases": False,
                "usesPersonalInfo": False,
                "isChildDirected": False,
                "isExportCompliant": True,
                "containsAds": False,
                "locales": {LOCALE: {}, GERMAN: {}},
            },
        }
    }
