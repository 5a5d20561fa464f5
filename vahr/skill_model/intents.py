"""The skill's intents as data: slots, sample utterances and elicitation samples.

The generator turns these, together with `fleet.yaml`, into the interaction model. Sample
utterances follow Alexa's rules: lower-case words, numbers spelled out, no punctuation
other than apostrophes, and `{slot}` references surrounded by spaces. No utterance, and no
utterance shape once slot names are replaced by their types, may appear in two intents:
the generator refuses to write a model that breaks this.
"""

from __future__ import annotations

from dataclasses import dataclass

LOCALE = "en-US"
ROBOT_TYPE = "ROBOT"
ZONE_TYPE = "ZONE"

# The answers a person (or a robot) gives when the skill elicits one slot.
ROBOT_ANSWERS = ("{slot}", "use {slot}", "with {slot}", "i mean {slot}", "i want {slot}")
ZONE_ANSWERS = ("{slot}", "to {slot}", "go to {slot}", "deliver it to {slot}", "i mean {slot}")


@dataclass(frozen=True)
class SlotSpec:
    """One slot: its name in requests, its type, and what a person says when asked for it."""

    name: str
    type: str

    @property
    def answers(self) -> list[str]:
        template = ROBOT_ANSWERS if self.type == ROBOT_TYPE else ZONE_ANSWERS
        return [answer.replace("{slot}", "{" + self.name + "}") for answer in template]


@dataclass(frozen=True)
class IntentSpec:
    """A custom intent: its slots and at least one sample utterance per phrasing."""

    name: str
    slots: tuple[SlotSpec, ...] = ()
    samples: tuple[str, ...] = ()
    # Robot-command intents need at least 15 varied samples (a test holds them to it).
    commands_robots: bool = False


ROBOT = SlotSpec("robot", ROBOT_TYPE)
ZONE = SlotSpec("zone", ZONE_TYPE)

NAVIGATE = IntentSpec(
    name="NavigateIntent",
    slots=(ROBOT, ZONE),
    commands_robots=True,
    samples=(
        "send {robot} to {zone}",
        "send {robot} over to {zone}",
        "move {robot} to {zone}",
        "drive {robot} to {zone}",
        "navigate {robot} to {zone}",
        "tell {robot} to go to {zone}",
        "tell {robot} to drive to {zone}",
        "have {robot} go to {zone}",
        "make {robot} go to {zone}",
        "get {robot} over to {zone}",
        "bring {robot} to {zone}",
        "take {robot} to {zone}",
        "direct {robot} to {zone}",
        "{robot} go to {zone}",
        "{robot} move to {zone}",
        "{robot} drive to {zone}",
        "{robot} head to {zone}",
        "i want {robot} in {zone}",
        "send {robot}",
        "move {robot}",
        "send a robot to {zone}",
        "navigate to {zone}",
    ),
)

DELIVER = IntentSpec(
    name="DeliverIntent",
    slots=(ROBOT, ZONE),
    commands_robots=True,
    samples=(
        "have {robot} deliver a package to {zone}",
        "tell {robot} to deliver a package to {zone}",
        "ask {robot} to deliver a package to {zone}",
        "use {robot} to deliver a package to {zone}",
        "{robot} deliver a package to {zone}",
        "{robot} deliver to {zone}",
        "let {robot} deliver to {zone}",
        "deliver a package to {zone} with {robot}",
        "send a package to {zone} with {robot}",
        "have {robot} take a package to {zone}",
        "have {robot} carry a package to {zone}",
        "tell {robot} to bring a package to {zone}",
        "{robot} bring a package to {zone}",
        "{robot} pick up a package and take it to {zone}",
        "have {robot} pick up a package for {zone}",
        "have {robot} make a delivery to {zone}",
        "have {robot} deliver a package",
        "start a delivery with {robot}",
        "deliver a package to {zone}",
        "make a delivery to {zone}",
        "deliver a package",
    ),
)

WEATHER_DELIVERY = IntentSpec(
    name="WeatherDeliveryIntent",
    slots=(ROBOT,),
    commands_robots=True,
    samples=(
        "have {robot} deliver based on the weather",
        "have {robot} deliver according to the weather",
        "{robot} deliver depending on the weather",
        "tell {robot} to do the weather delivery",
        "start the weather delivery with {robot}",
        "weather delivery with {robot}",
        "have {robot} ask about the weather and deliver",
        "let {robot} check the weather and deliver",
        "{robot} make a weather delivery",
        "ask {robot} to make a delivery based on the weather",
        "send {robot} on a weather delivery",
        "use {robot} for the weather delivery",
        "{robot} find out the weather and deliver a package",
        "tell {robot} to deliver wherever the weather says",
        "run the weather task with {robot}",
        "start a weather delivery",
        "deliver based on the weather",
    ),
)

FIRST_ROBOT = SlotSpec("firstRobot", ROBOT_TYPE)
FIRST_ZONE = SlotSpec("firstZone", ZONE_TYPE)
SECOND_ROBOT = SlotSpec("secondRobot", ROBOT_TYPE)
SECOND_ZONE = SlotSpec("secondZone", ZONE_TYPE)

SEQUENTIAL_DELIVERY = IntentSpec(
    name="SequentialDeliveryIntent",
    slots=(FIRST_ROBOT, FIRST_ZONE, SECOND_ROBOT, SECOND_ZONE),
    commands_robots=True,
    samples=(
        "{firstRobot} deliver to {firstZone} then {secondRobot} deliver to {secondZone}",
        "have {firstRobot} deliver to {firstZone} and then {secondRobot} deliver to {secondZone}",
        "first {firstRobot} delivers to {firstZone} then {secondRobot} delivers to {secondZone}",
        "deliver to {firstZone} with {firstRobot} and then to {secondZone} with {secondRobot}",
        "have {firstRobot} deliver to {firstZone} and after that {secondRobot} to {secondZone}",
        "have {secondRobot} deliver to {secondZone} after {firstRobot} delivers to {firstZone}",
        "sequential delivery with {firstRobot} to {firstZone} and {secondRobot} to {secondZone}",
        "make a sequential delivery with {firstRobot} and {secondRobot}",
        "let {firstRobot} deliver first and {secondRobot} second",
        "{firstRobot} delivers first then {secondRobot}",
        "sequential delivery to {firstZone} and {secondZone}",
        "take turns delivering to {firstZone} and {secondZone}",
        "deliver to {firstZone} and {secondZone} one after the other",
        "start a sequential delivery with {firstRobot}",
        "start a sequential delivery",
        "do a sequential delivery",
        "deliver one after the other",
    ),
)

STATUS = IntentSpec(
    name="StatusIntent",
    slots=(ROBOT,),
    samples=(
        "where is {robot}",
        "where's {robot}",
        "where are {robot}",
        "what is {robot} doing",
        "what's {robot} doing",
        "what are {robot} doing",
        "what's {robot} up to",
        "how is {robot} doing",
        "status of {robot}",
        "give me the status of {robot}",
        "check on {robot}",
        "is {robot} busy",
        "where are the robots",
        "what are the robots doing",
        "give me a status report",
        "fleet status",
        "robot status",
    ),
)

EMERGENCY_STOP = IntentSpec(
    name="EmergencyStopIntent",
    slots=(ROBOT,),
    commands_robots=True,
    samples=(
        "emergency stop",
        "emergency stop {robot}",
        "emergency stop for {robot}",
        "hit the emergency stop",
        "stop {robot}",
        "stop {robot} now",
        "stop {robot} immediately",
        "halt {robot}",
        "freeze {robot}",
        "{robot} stop",
        "{robot} halt",
        "{robot} freeze",
        "{robot} stop moving",
        "tell {robot} to stop",
        "make {robot} stop",
        "stop all motion",
        "halt everything",
        "freeze everything",
    ),
)

WEATHER = IntentSpec(
    name="WeatherIntent",
    samples=(
        "what is the weather",
        "what's the weather",
        "what is the weather like",
        "what's the weather like",
        "what is the weather today",
        "what's the weather today",
        "how is the weather",
        "how's the weather",
        "tell me the weather",
        "give me the weather",
        "is it sunny or rainy",
        "is it sunny",
        "is it rainy",
        "is it raining",
        "what's the weather for the experiment",
        # The robots' own question (vahr.protocol.assistant.WEATHER_QUESTION) and its variants.
        "what the weather is",
        "what the weather is like",
        "tell me what the weather is",
    ),
)

CUSTOM_INTENTS: tuple[IntentSpec, ...] = (
    NAVIGATE,
    DELIVER,
    WEATHER_DELIVERY,
    SEQUENTIAL_DELIVERY,
    STATUS,
    EMERGENCY_STOP,
    WEATHER,
)

BUILT_IN_INTENTS: tuple[str, ...] = (
    "AMAZON.HelpIntent",
    "AMAZON.CancelIntent",
    "AMAZON.StopIntent",
    "AMAZON.NavigateHomeIntent",
    "AMAZON.FallbackIntent",
)
