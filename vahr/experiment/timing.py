"""The simulated participant's timing model, for speaking and for clicking.

Clicking follows the Keystroke-Level Model (Card, Moran and Newell, 1980): before each
command the person prepares mentally (M = 1.35 s) and moves a hand from the puzzle to the
mouse (H = 0.4 s); each button is one pointing movement (P = 1.1 s) and one press and release
(BB = 0.2 s). A command in the console is four buttons: robot, action, zone, send.

Speaking: mental preparation (M), the wake word ("Alexa", 0.6 s), then the utterance at a
conversational 150 words per minute; the assistant's reply is listened to at 175 words per
minute, a typical rate for Alexa's voice. The assistant's own processing time is not
modelled: it is whatever the real system takes.

While the robots work, the participant solves the jigsaw puzzle: the time per piece is
exponentially distributed with a mean of 25 s. Every duration gets a small seeded
Gaussian jitter (10 %) so runs differ the way people do, yet replay exactly with one seed.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    import random


@dataclass(frozen=True)
class TimingModel:
    mental_s: float = 1.35
    home_s: float = 0.4
    point_s: float = 1.1
    press_s: float = 0.2
    wake_word_s: float = 0.6
    speaking_wpm: float = 150.0
    reply_wpm: float = 175.0
    puzzle_piece_mean_s: float = 25.0
    jitter: float = 0.10

    def _jittered(self, rng: random.Random, seconds: float) -> float:
        return max(0.0, seconds * (1 + rng.gauss(0, self.jitter)))

    def speaking_s(self, rng: random.Random, text: str) -> float:
        """From starting to speak (mental preparation first) to the end of the utterance."""
        words = len(text.split())
        return self._jittered(
            rng, self.mental_s + self.wake_word_s + words * 60 / self.speaking_wpm
        )

    def listening_s(self, rng: random.Random, reply: str) -> float:
        """Listening to the assistant's spoken reply to its end."""
        return self._jittered(rng, len(reply.split()) * 60 / self.reply_wpm)

    def first_click_s(self, rng: random.Random) -> float:
        """The first button of a command: M + H + P + BB."""
        return self._jittered(rng, self.mental_s + self.home_s + self.point_s + self.press_s)

    def next_click_s(self, rng: random.Random) -> float:
        """Every further button of the same command: P + BB."""
        return self._jittered(rng, self.point_s + self.press_s)

    def puzzle_piece_s(self, rng: random.Random) -> float:
        return rng.expovariate(1 / self.puzzle_piece_mean_s)
