"""Shared phrases of the sample templates: the ways people open, soften and end a request.

Each rule is a template (see `vahr.skill_model.templates`) that intents insert with
`<name>`. They hold the words that vary between speakers without changing what is asked:
politeness, fillers, the carrier verbs for moving and carrying, and the names of the cargo.
Slot values (robot, zone and group names) never appear here: they live in fleet.yaml.
"""

from __future__ import annotations

from vahr.domain.weather import SAMPLED_WEATHER_WORDS

_SUNNY, _RAINY = ("|".join(SAMPLED_WEATHER_WORDS[w]) for w in ("sunny", "rainy"))

RULES: dict[str, str] = {
    # How a request opens: bare, polite, indirect, or with a filler first.
    "ask": (
        "[please|could you|can you|would you|will you|could you please|can you please"
        "|would you please|could you kindly|would you kindly|kindly|i want you to|i'd like you to"
        "|i need you to|go ahead and"
        "|okay|ok|so|um|uh|hey|now|alright]"
    ),
    # How it ends.
    "end": "[please|now|right now|for me|thanks|thank you|now please|asap|when you can]",
    # Driving somewhere, said of the robot ("placebot one, go to zone b").
    "go": "(go|move|drive|head|travel|roll|navigate|proceed|make your way|get yourself)",
    "goes": "(go|move|drive|head|travel|roll|navigate|make its way|get)",
    # Sending a robot somewhere, said to the assistant ("send placebot one to zone b").
    "send": "(send|move|drive|take|bring|get|direct|dispatch|navigate|route|steer|guide)",
    "way": "[over|back|down|across|up|on over]",
    "to": "(to|into|towards|toward|over to)",
    # Carrying something, and what is carried.
    "carry": "(deliver|bring|take|carry|transport|haul|ship|drop)",
    "cargo": (
        "((a|the|one|this|that|another) (package|parcel|box|delivery|load|item|shipment|crate)"
        "|the green (package|box)|some cargo|the cargo|it|something|a package over)"
    ),
    "weather_basis": (
        "(based on|depending on|according to|depending upon|dependent on|following"
        "|in line with) the weather"
    ),
    "weather_job": "the weather (delivery|task|navigation|run|job|mission|errand)",
    # A condition of the weather delivery's rule, in the words of
    # vahr.domain.weather.SAMPLED_WEATHER_WORDS.
    "if_sunny": f"(if|when|in case) [it's|it is|the weather is] ({_SUNNY})",
    "if_rainy": f"(if|when|in case) [it's|it is|the weather is] ({_RAINY})",
}
