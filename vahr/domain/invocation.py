"""How people and robots address the assistant: the wake word and the skill's invocation
name, and the question a robot asks for the weather.

The interaction model is generated with this invocation name (`python -m vahr.skill_model`),
the skill introduces itself with it, and the room assistant listens for it.
"""

from __future__ import annotations

WAKE_WORD = "alexa"
INVOCATION_NAME = "robot fleet"
# What a robot says to the assistant for task II (a WeatherIntent sample, test_skill_model).
WEATHER_QUESTION = f"Alexa, ask {INVOCATION_NAME} what the weather is"
# Alexa's built-in intent for words the skill's model does not cover: the interaction model
# declares it, the simulator's NLU answers with it, and the skill and the station act on it.
FALLBACK_INTENT = "AMAZON.FallbackIntent"
