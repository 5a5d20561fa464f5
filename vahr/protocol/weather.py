"""The weather of the paper's task II: the words and the zone each one sends a robot to.

The skill speaks the weather, robots hear it and deliver, the experiment draws and judges
it; all of them take these facts from here.
"""

from __future__ import annotations

from typing import Literal

Weather = Literal["sunny", "rainy"]
WEATHERS: tuple[Weather, ...] = ("sunny", "rainy")
# Deliver to A when it is sunny, to C when it is rainy (DESIGN.md, weather_delivery).
WEATHER_ZONES: dict[Weather, str] = {"sunny": "A", "rainy": "C"}
