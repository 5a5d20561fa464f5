"""The weather of the paper's task II: the weathers, the zone each one sends a robot to, and
the English words people name them and deny them with.

The skill speaks the weather, robots hear it and deliver, the experiment draws and judges
it; all of them take these facts from here. The skill's sample utterances and the
simulator's NLU name a weather with `WEATHER_WORDS`; the NLU and the robot's hearing deny
one with `NEGATIONS`. The robot's hearing decides by the cues of the assistant's answers
(`robot_agent/voice/weather_answers.yaml`: phrases such as "clear skies" and "cats and
dogs", weak and denied cues), which its recognizer and its tuning sets are built on.
"""

from __future__ import annotations

from typing import Literal

Weather = Literal["sunny", "rainy"]
WEATHERS: tuple[Weather, ...] = ("sunny", "rainy")
# Deliver to A when it is sunny, to C when it is rainy (DESIGN.md, weather_delivery).
WEATHER_ZONES: dict[Weather, str] = {"sunny": "A", "rainy": "C"}

# The words a rule's condition is said with in the skill's sample utterances ("if it's nice").
SAMPLED_WEATHER_WORDS: dict[Weather, tuple[str, ...]] = {
    "sunny": ("sunny", "nice", "clear", "dry"),
    "rainy": ("rainy", "raining", "wet", "pouring"),
}
# Every word the simulator's NLU reads as naming a weather beside a zone of the weather
# delivery's rule: those, and others people say.
WEATHER_WORDS: dict[Weather, tuple[str, ...]] = {
    "sunny": (*SAMPLED_WEATHER_WORDS["sunny"], "sunshine", "sun", "fine", "bright"),
    "rainy": (*SAMPLED_WEATHER_WORDS["rainy"], "rain", "rains", "showers", "drizzle", "stormy"),
}
# The plain negations: the NLU reads a weather said just after one as the other ("if it's not
# sunny", "no rain").
PLAIN_NEGATIONS: tuple[str, ...] = ("not", "isn't", "no")
# Every word that denies what follows it: the robot's hearing takes a cue after one as said
# of no weather ("it won't rain", "not a single cloud", "leave the umbrella at home").
NEGATIONS: tuple[str, ...] = (
    *PLAIN_NEGATIONS,
    *("never", "without", "nor", "none", "aren't", "wasn't", "won't", "don't", "doesn't"),
    *("didn't", "can't", "shouldn't", "wouldn't", "hardly", "nothing", "leave"),
)
