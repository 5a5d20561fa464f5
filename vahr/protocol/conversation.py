"""What the skill and the assistant agree on about a conversation's memory.

The skill keeps the last command it sent in the session's attributes under
`LAST_COMMAND_ATTRIBUTE`, so that "no, zone b" or "cancel that" can redirect or stop it.
Alexa forgets a session's attributes when the session ends; the local assistant keeps that
one attribute for `CORRECTION_WINDOW_S` more seconds for the same speaker (`speaker`), so a
correction said just after a one-shot request still reaches the command it corrects.
"""

from __future__ import annotations

LAST_COMMAND_ATTRIBUTE = "lastCommand"
# Long enough to hear what the robot did and say "no, zone b"; short enough that a later
# "cancel that" is not taken to mean a command the speaker has long forgotten.
CORRECTION_WINDOW_S = 30.0


def speaker(origin: str) -> str:
    """Who spoke a turn of this origin, as far as corrections go: the origin up to its first
    "-". The station's typed words ("station"), its weather button ("station-weather") and
    its push-to-talk ("station-voice") are one person at one station, who may say a command
    and type its correction."""
    return origin.split("-", 1)[0]
