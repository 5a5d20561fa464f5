"""The simulated participant's timing: every constant with its source, and the operators.

A participant's time is built from published operators, never fitted to the paper's
Table II (see docs/experiment.md, "The participant model"):

- clicking on the station's map: the Keystroke-Level Model (KLM) operators M (mental
  preparation), H (homing the hand between the puzzle and the mouse) and B (a button press
  or release; a click is BB), and Fitts's law for each pointing movement, with the targets'
  sizes and distances taken from the map drawn to scale;
- speaking to the assistant: mental preparation, then the words at a conversational rate;
  the assistant's reply is listened to at its voice's rate; an utterance prepared while the
  previous reply played starts one turn-taking gap after it;
- monitoring: a glance at the screen is two eye movements, a perceptual and a cognitive
  cycle of the Model Human Processor; the participant glances up at each puzzle part's end
  (a breakpoint) while a robot is on a leg whose end they must see;
- the puzzle: parts are solved at the paper's rate, parts over neglect time.

Each participant gets one tempo factor, drawn once from a seeded generator, that scales
every human operator (not the assistant's voice, not the puzzle rate): people differ, and
the KLM's own validation put individual users about 21 % from its predictions.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    import random

    from vahr.domain import Pose


@dataclass(frozen=True)
class Constant:
    """A number the model uses, with its unit and where it comes from."""

    value: float
    unit: str
    source: str


CMN_1980 = (
    "Card, Moran & Newell (1980), The keystroke-level model for user performance time "
    "with interactive systems, CACM 23(7):396-410"
)
CMN_1983 = (
    "Card, Moran & Newell (1983), The Psychology of Human-Computer Interaction, ch. 2 "
    "(Model Human Processor, Middleman values)"
)

MENTAL_PREPARATION = Constant(1.35, "s", f"KLM operator M; {CMN_1980}")
HOMING = Constant(0.40, "s", f"KLM operator H; {CMN_1980}")
BUTTON = Constant(
    0.10,
    "s",
    "KLM operator B, one mouse-button press or release (a click is BB = 0.2 s); Kieras "
    "(2001), Using the Keystroke-Level Model to Estimate Execution Times, Univ. of Michigan",
)
FITTS_INTERCEPT = Constant(
    -0.107,
    "s",
    "mouse pointing, MT = a + b log2(D/W + 1); MacKenzie, Sellen & Buxton (1991), A "
    "comparison of input devices in elemental pointing and dragging tasks, CHI '91; the "
    "Shannon formulation as in MacKenzie (1992), HCI 7:91-139",
)
FITTS_SLOPE = Constant(
    0.223,
    "s/bit",
    "mouse pointing slope b (index of performance 4.5 bits/s); MacKenzie, Sellen & Buxton "
    "(1991), CHI '91",
)
MAP_SCALE = Constant(
    80.0,
    "px/m",
    "assumed station layout: the floor of fleet.yaml drawn to scale on the station's map "
    "panel (docs/experiment.md, The station's map); the station must keep it",
)
ROBOT_MARKER = Constant(
    0.6,
    "m",
    "assumed station layout: a robot's clickable marker, drawn to scale (docs/experiment.md, "
    "The station's map); a zone's target is its circle of fleet.yaml's radius",
)
SPEAKING_RATE = Constant(
    150.0,
    "words/min",
    "average conversational rate of American English; National Center for Voice and "
    "Speech (NCVS), Voice qualities: speaking rate (about 150 wpm, cited 2014)",
)
ASSISTANT_SPEAKING_RATE = Constant(
    175.0,
    "words/min",
    "the assistant's synthetic voice in the local stack: espeak-ng's default speed, "
    "espeak-ng(1) manual (-s, default 175 wpm; espeak-ng 1.51, 2022)",
)
TURN_GAP = Constant(
    0.2,
    "s",
    "gap before a prepared next turn; Stivers et al. (2009), Universals and cultural "
    "variation in turn-taking in conversation, PNAS 106(26):10587-10592; Levinson & "
    "Torreira (2015), Front. Psychol. 6:731",
)
EYE_MOVEMENT = Constant(0.23, "s", f"eye-movement time (saccade and fixation); {CMN_1983}")
PERCEPTUAL_CYCLE = Constant(0.10, "s", f"perceptual processor cycle time; {CMN_1983}")
COGNITIVE_CYCLE = Constant(0.07, "s", f"cognitive processor cycle time; {CMN_1983}")
PUZZLE_RATE = Constant(
    (13 + 8) / (142 + 59),
    "parts/s of neglect time",
    "the paper's Table II: 13 + 8 puzzle parts over 142 + 59 s of neglect time (VAHR and "
    "keyboard and mouse pooled: the puzzle and the people were the same in both)",
)
GLANCES_PER_PART = Constant(
    1.0,
    "glances per puzzle part",
    "people switch tasks at subtask boundaries (breakpoints); Adamczyk & Bailey (2004), If "
    "not now, when?, CHI '04; Iqbal & Bailey (2005), CHI '05 EA: while a robot must be "
    "watched, the participant looks up each time a puzzle part is done",
)
TEMPO_SPREAD = Constant(
    0.21,
    "log-SD of a participant's tempo factor",
    f"the KLM predicted individual users' times with a 21 % root-mean-square error; {CMN_1980}",
)

CONSTANTS: dict[str, Constant] = {
    name: value for name, value in dict(globals()).items() if isinstance(value, Constant)
}


def screen_point(pose: Pose) -> tuple[float, float]:
    """Where a pose of the floor is on the station's map, in pixels."""
    return pose.x * MAP_SCALE.value, pose.y * MAP_SCALE.value


def fitts_s(distance_px: float, width_px: float) -> float:
    """Mouse pointing time by Fitts's law (Shannon formulation), never below zero."""
    index = math.log2(distance_px / width_px + 1)
    return max(0.0, FITTS_INTERCEPT.value + FITTS_SLOPE.value * index)


MONITORING = ("glance", "watch", "announce")


@dataclass(frozen=True)
class Person:
    """One simulated participant: how fast they are relative to the KLM's average person,
    and how they monitor a robot whose arrival they wait for: `glance` (the model above:
    a look at each puzzle part's end), `watch` (eyes on the screen until it happens; a
    sensitivity variant with no constant of its own, see docs/experiment.md) or `announce`
    (never looks; hears the assistant announce each finished task, `hearing_s`)."""

    tempo: float = 1.0
    monitoring: str = "glance"

    @classmethod
    def draw(cls, rng: random.Random, monitoring: str = "glance") -> Person:
        """A participant with a log-normal tempo around 1 (seeded, so a study replays)."""
        if monitoring not in MONITORING:
            raise ValueError(f"monitoring is one of {', '.join(MONITORING)}, not {monitoring!r}")
        return cls(tempo=math.exp(rng.gauss(0.0, TEMPO_SPREAD.value)), monitoring=monitoring)

    def mental_s(self) -> float:
        return MENTAL_PREPARATION.value * self.tempo

    def homing_s(self) -> float:
        return HOMING.value * self.tempo

    def click_s(self) -> float:
        """One click: BB."""
        return 2 * BUTTON.value * self.tempo

    def point_s(
        self, start: tuple[float, float], end: tuple[float, float], width_m: float
    ) -> float:
        """Pointing from `start` to a target of `width_m` (metres of floor) at `end`."""
        distance = math.dist(start, end)
        return fitts_s(distance, width_m * MAP_SCALE.value) * self.tempo

    def speaking_s(self, text: str) -> float:
        """Saying `text` (every word, the wake word included) at the speaking rate."""
        return len(text.split()) * 60 / SPEAKING_RATE.value * self.tempo

    def turn_gap_s(self) -> float:
        return TURN_GAP.value * self.tempo

    def hearing_s(self, announcement: str) -> float:
        """Noticing an announcement and taking it in: a perceptual and a cognitive cycle
        (the Model Human Processor's, as a glance has them), then listening to it to its end
        at the assistant's rate (`listening_s`)."""
        return (PERCEPTUAL_CYCLE.value + COGNITIVE_CYCLE.value) * self.tempo + listening_s(
            announcement
        )

    def glance_s(self) -> float:
        """A look at the screen and back: two eye movements, perceive, decide."""
        return (
            2 * EYE_MOVEMENT.value + PERCEPTUAL_CYCLE.value + COGNITIVE_CYCLE.value
        ) * self.tempo


def listening_s(reply: str) -> float:
    """Hearing the assistant's reply to its end, at its voice's rate."""
    return len(reply.split()) * 60 / ASSISTANT_SPEAKING_RATE.value


def puzzle_part_s(rng: random.Random) -> float:
    """Puzzle time until the next part is done (exponential: an interrupted part resumes)."""
    return rng.expovariate(PUZZLE_RATE.value)
