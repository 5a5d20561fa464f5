"""The skill's intents as data: slots, sample-utterance templates and elicitation samples.

The generator expands each intent's templates (alternatives, optional words and the shared
phrases of `vahr.skill_model.phrases`) into sample utterances and, together with
`fleet.yaml`, writes the interaction model. Sample utterances follow Alexa's rules:
lower-case words, numbers spelled out, no punctuation other than apostrophes, and `{slot}`
references surrounded by spaces. No utterance, and no utterance shape once slot names are
replaced by their types, may appear in two intents: the generator refuses to write a model
that breaks this.
"""

from __future__ import annotations

import json
import random
from dataclasses import dataclass
from functools import cached_property

from vahr.domain.invocation import FALLBACK_INTENT
from vahr.model_cache import code_digest, content_key, default_cache_dir, write_atomically
from vahr.skill_model import templates
from vahr.skill_model.phrases import RULES
from vahr.skill_model.templates import draw

LOCALE = "en-US"
ROBOT_TYPE = "ROBOT"
ZONE_TYPE = "ZONE"
# The fleet's groups other than the whole fleet, and how many robots (fleet dispatch).
GROUP_TYPE = "GROUP"
COUNT_TYPE = "COUNT"
# A battery's charge in percent ("which robots are below thirty percent").
PERCENT_TYPE = "PERCENT"
# How many expanded samples an intent keeps at most: enough variety for Alexa (and the
# simulator's classifier) to generalize, far inside the model's size limits (generator.py).
MAX_SAMPLES_PER_INTENT = 240

# The answers a person (or a robot) gives when the skill elicits one slot.
ROBOT_ANSWERS = ("{slot}", "use {slot}", "with {slot}", "i mean {slot}", "i want {slot}")
ZONE_ANSWERS = ("{slot}", "to {slot}", "go to {slot}", "deliver it to {slot}", "i mean {slot}")
GROUP_ANSWERS = ("{slot}", "i mean {slot}")
COUNT_ANSWERS = ("{slot}", "{slot} robots")
PERCENT_ANSWERS = ("{slot}", "{slot} percent")


@dataclass(frozen=True)
class SlotSpec:
    """One slot: its name in requests, its type, and what a person says when asked for it."""

    name: str
    type: str

    @property
    def answers(self) -> list[str]:
        template = {
            ROBOT_TYPE: ROBOT_ANSWERS,
            GROUP_TYPE: GROUP_ANSWERS,
            COUNT_TYPE: COUNT_ANSWERS,
            PERCENT_TYPE: PERCENT_ANSWERS,
        }.get(self.type, ZONE_ANSWERS)
        return [answer.replace("{slot}", "{" + self.name + "}") for answer in template]


@dataclass(frozen=True)
class IntentSpec:
    """A custom intent: its slots and the templates its sample utterances expand from."""

    name: str
    slots: tuple[SlotSpec, ...] = ()
    templates: tuple[str, ...] = ()
    # Samples kept whatever the draw: the skill's example phrases, the question robots ask,
    # and the simulated participant's script (vahr.experiment.participant).
    essentials: tuple[str, ...] = ()
    # Robot-command intents need at least 60 varied samples (a test holds them to it).
    commands_robots: bool = False
    # How many samples it keeps at most: more for an intent said in many more ways, so that
    # templates added for a new way do not crowd out the ways it had.
    max_samples: int = MAX_SAMPLES_PER_INTENT

    @cached_property
    def samples(self) -> list[str]:
        """The expanded samples: every template contributes in turn, up to the cap.

        Each template's sentences are drawn and shuffled with a seed made of the intent's
        name, so the choice is varied (not the first words of every alternative) and the
        same on every run. Drawing every intent's takes a second of CPU at each start of
        `vahr up`; they depend on nothing but this spec, the shared phrases and the code
        that draws them, so they are kept in the model cache under a hash of those.
        """
        drawing = code_digest(__name__, templates.__name__)
        made_from = [drawing, self.name, self.templates, self.essentials, self.max_samples,
                     MAX_SAMPLES_PER_INTENT, RULES]  # fmt: skip
        key = content_key(made_from)
        file = default_cache_dir() / f"samples-{self.name}-{key[:24]}.json"
        try:
            kept = json.loads(file.read_bytes())
            if kept["key"] == key:
                return list(kept["samples"])
        except (OSError, ValueError, KeyError, TypeError):
            pass  # not drawn yet here, or damaged: drawn again
        drawn = self._drawn()
        write_atomically(file, json.dumps({"key": key, "samples": drawn}).encode())
        return drawn

    def _drawn(self) -> list[str]:
        rng = random.Random(f"{self.name}:samples")
        pools: list[list[str]] = []
        for template in self.templates:
            expansions = draw(template, RULES, rng, MAX_SAMPLES_PER_INTENT)
            rng.shuffle(expansions)
            pools.append(expansions)
        chosen: dict[str, None] = dict.fromkeys(self.essentials)
        while len(chosen) < self.max_samples and any(pools):
            for pool in pools:
                if pool and len(chosen) < self.max_samples:
                    chosen.setdefault(pool.pop(), None)
        return list(chosen)


ROBOT = SlotSpec("robot", ROBOT_TYPE)
ZONE = SlotSpec("zone", ZONE_TYPE)

NAVIGATE = IntentSpec(
    name="NavigateIntent",
    slots=(ROBOT, ZONE),
    commands_robots=True,
    # The templates for a robot meant but not named ("move the robot to zone b") came
    # last, and the cap grew by their share of the draw (seven of 50 templates), so that
    # they add to the samples rather than take the places of the other ways of saying it.
    max_samples=MAX_SAMPLES_PER_INTENT + 40,
    essentials=(
        "send {robot} to {zone}",
        "move {robot} to {zone}",
        "{robot} go to {zone}",
        "bring {robot} to {zone}",
    ),
    templates=(
        "<ask> <send> {robot} <way> <to> {zone} <end>",
        "<ask> (tell|ask|get) {robot} to <go> <way> <to> {zone} <end>",
        "<ask> (have|let|make) {robot} <go> <way> <to> {zone} <end>",
        "{robot} <goes> <way> <to> {zone} <end>",
        "{robot} (please|can you|could you|i need you to|you need to|i want you to) <go> <way> "
        "<to> {zone}",
        "{robot} (should|needs to|has to|must|can) <go> <way> <to> {zone} <end>",
        "(i want|i need|i'd like|put|park|position|station) {robot} (in|at|over at|by) {zone}",
        "(i want|i need|i'd like) {robot} to <go> <way> <to> {zone} <end>",
        "{robot} <to> {zone} <end>",
        "{robot} {zone} <end>",
        "<ask> (navigate|drive|head) {robot} <way> <to> {zone}",
        "<ask> (send|move|take|drive|get) {robot} <way> (there|to it|to that zone)",
        "<ask> (send|move|dispatch) {robot} <end>",
        # "send a robot to zone b" is FleetNavigateIntent: the fleet picks the robot.
        "<ask> (send|move|dispatch) (one|some) (robot|bot) <way> <to> {zone} <end>",
        "<ask> (navigate|drive|head) <way> <to> {zone} <end>",
        "<ask> (start|begin) (navigating|driving|moving|heading) <to> {zone} with {robot}",
        "<ask> (move|relocate|reposition) {robot} (over|across) <to> {zone}",
        "<ask> (let's|lets) (get|send|move|take) {robot} <way> <to> {zone}",
        "<ask> (bring|get|send) {robot} <way> (here|over) to {zone}",
        "<ask> (get|set|start) {robot} (moving|going|driving|heading|rolling) <way> <to> {zone}",
        "<ask> (go|drive|head|move) <way> <to> {zone} (with|using|on) {robot} <end>",
        "(next|then|and then|and now|now|after that) {robot} <goes> <way> <to> {zone} <end>",
        "{robot} (is loaded|has its package|got its package|is ready|you are loaded|you're "
        "loaded|you have your package) [so|now|so now] <go> <way> <to> {zone} <end>",
        "{robot} (is loaded|has its package|got its package|is ready) [so|now|so now] (send|move|"
        "take|get) it <way> <to> {zone}",
        "[<ask>] (for|with) {robot} the zone is {zone} [so] (send it|go|move it) there",
        "{robot} your zone is {zone} [so] (go|head|drive) there <end>",
        "(it's|it is|the weather is) (sunny|raining|rainy) [so|and] {robot} <go> <way> <to> {zone}",
        "(since|because|as) (it's|it is) (sunny|raining|rainy) (send|move|take) {robot} <to> "
        "{zone}",
        "(it's|it is|the weather is) (sunny|raining|rainy) [today|now] [so] (send|move|take|get) "
        "{robot} <way> <to> {zone} <end>",
        "(sunny|rainy|raining|it's sunny|it's raining) [today|then] [so] {robot} <to> {zone} <end>",
        "<ask> (take|bring|walk|drive) {robot} <way> <to> {zone} <end>",
        "<to> {zone} (with|for) {robot} <end>",
        "{zone} for {robot} <end>",
        "{robot} <go> <way> <to> {zone} (to|and) (pick up|get|collect|grab|fetch) (the|a|its|your) "
        "(package|box|parcel|load)",
        "(and|and then|then) {robot} <to> {zone} [as well|too|please]",
        # A robot meant but not named ("move the robot to zone b"): one robot, still to be
        # asked for, unlike "a robot" (the fleet picks) or "the robots in zone a" (those).
        "<ask> <send> (the|my|that|this|your) (robot|bot) <way> <to> {zone} <end>",
        "<ask> (move|relocate|reposition|drive) (the|my|that|this) (robot|bot) (over|across) "
        "<to> {zone}",
        "(the|my|that|this) (robot|bot) (should|needs to|has to|can|please) <go> <way> <to> "
        "{zone} <end>",
        "<ask> (tell|ask|get) (the|my|that|this) (robot|bot) to <go> <way> <to> {zone} <end>",
        "<ask> (have|let|make) (the|my|that|this) (robot|bot) <go> <way> <to> {zone} <end>",
        "(i want|i need|i'd like|put|park) (the|my|that|this) (robot|bot) (in|at|over at) "
        "{zone} <end>",
        "(the|my|that|this) (robot|bot) <to> {zone} <end>",
    ),
)

DELIVER = IntentSpec(
    name="DeliverIntent",
    slots=(ROBOT, ZONE),
    commands_robots=True,
    essentials=(
        "have {robot} deliver a package to {zone}",
        "deliver a package to {zone}",
        "have {robot} deliver",
        "let {robot} deliver",
        "tell {robot} to deliver a package to {zone}",
        "deliver to {zone}",
    ),
    templates=(
        "<ask> (have|let|make) {robot} <carry> <cargo> <way> to {zone} <end>",
        "<ask> (tell|ask|get) {robot} to <carry> <cargo> <way> to {zone} <end>",
        "{robot} <carry> <cargo> <way> to {zone} <end>",
        "{robot} (please|can you|could you|i need you to|you need to) <carry> <cargo> <way> "
        "to {zone}",
        "{robot} (should|needs to|has to|will) <carry> <cargo> <way> to {zone} <end>",
        "(i want|i need|i'd like) {robot} to <carry> <cargo> <way> to {zone} <end>",
        "<ask> <carry> <cargo> <way> to {zone} (with|using|on|via) {robot} <end>",
        "<ask> (use|with) {robot} to <carry> <cargo> to {zone}",
        "{robot} (pick up|grab|fetch|collect|load up|get) <cargo> and (deliver|bring|take|carry) "
        "it to {zone}",
        "<ask> (have|let) {robot} (pick up|grab|fetch|collect|get) <cargo> (and|then|and then) "
        "(deliver|bring|take|carry|drop) it (to|at|off at) {zone}",
        "<ask> (make|do|run|start) a delivery to {zone} (with|using|on) {robot}",
        "{robot} (make|do|run) a delivery (to|for) {zone} <end>",
        "<ask> (have|let) {robot} (make|do|run) a delivery (to|for) {zone}",
        "{robot} deliver (to|at|for) {zone} <end>",
        "<ask> (have|let) {robot} deliver (to|at|for) {zone} <end>",
        "<ask> (tell|ask) {robot} to deliver (to|at|for) {zone} <end>",
        "<ask> (have|let) {robot} (deliver|make a delivery|do a delivery) [<cargo>] <end>",
        "<ask> (tell|ask|get) {robot} to (deliver|make a delivery|do a delivery) [<cargo>] <end>",
        "<ask> <carry> <cargo> <way> to {zone} <end>",
        "<ask> (make|do|run) a delivery to {zone} <end>",
        "<ask> (start|begin|do|make) a delivery (with|using) {robot}",
        "<ask> (deliver|ship|bring|send) <cargo> <end>",
        "<ask> (send|get) <cargo> (to|over to) {zone} (with|on|using) {robot}",
        "{robot} (deliver|drop) (the|a|one|this) (package|parcel|box) (in|at) {zone}",
    ),
)

# A person may say the weather delivery's rule aloud ("deliver to zone a if it's sunny and
# zone c if it's raining"); the skill holds what was said to the rule robots follow.
SUNNY_ZONE = SlotSpec("sunnyZone", ZONE_TYPE)
RAINY_ZONE = SlotSpec("rainyZone", ZONE_TYPE)

WEATHER_DELIVERY = IntentSpec(
    name="WeatherDeliveryIntent",
    slots=(ROBOT, SUNNY_ZONE, RAINY_ZONE),
    commands_robots=True,
    essentials=(
        "have {robot} deliver based on the weather",
        "tell {robot} to do the weather delivery",
    ),
    templates=(
        "<ask> (have|let|make) {robot} (deliver|make a delivery|do a delivery|navigate|go) "
        "<weather_basis> <end>",
        "<ask> (tell|ask|get) {robot} to (deliver|make a delivery|navigate|go) <weather_basis>",
        "{robot} (deliver|navigate|go|drive) <weather_basis> <end>",
        "{robot} (should|needs to|can) (deliver|navigate|go) <weather_basis>",
        "<ask> (have|let) {robot} (do|run|handle|take care of|start|perform) <weather_job> <end>",
        "<ask> (tell|ask|get) {robot} to (do|run|handle|start|perform) <weather_job> <end>",
        "<ask> (start|run|begin|do|kick off|launch) <weather_job> (with|for|using) {robot}",
        "<ask> (start|run|begin|do|kick off) a weather (delivery|task|navigation|run) (with|for|"
        "using) {robot}",
        "{robot} (do|run|start|handle) <weather_job> <end>",
        "<ask> (have|let) {robot} (check|ask about|find out|ask alexa about|ask for|look up) the "
        "weather (and|then|and then) (deliver|decide where to deliver|go to the right place)",
        "{robot} (check|ask about|find out) the weather (and|then|and then) deliver <cargo>",
        "<ask> send {robot} on (a|the) weather (delivery|run|mission|errand)",
        "<ask> (use|take) {robot} for <weather_job>",
        "{robot} deliver wherever the weather (says|tells you)",
        "<ask> (have|let) {robot} deliver (wherever|where) the weather (says|tells it)",
        "weather (delivery|navigation|task) (with|for) {robot} <end>",
        "<ask> (start|run|begin|do) <weather_job> <end>",
        "<ask> (start|run|begin|do) a weather (delivery|navigation|task|run) <end>",
        "<ask> (deliver|navigate) <weather_basis> <end>",
        # The rule said aloud, either weather first.
        "<ask> (have|let|tell) {robot} [to] (deliver|go) to {sunnyZone} <if_sunny> (and|or|but) "
        "[to] {rainyZone} <if_rainy>",
        "<ask> (have|let|tell) {robot} [to] (deliver|go) to {rainyZone} <if_rainy> (and|or|but) "
        "[to] {sunnyZone} <if_sunny>",
        "{robot} (deliver|go|drive) to {sunnyZone} <if_sunny> (and|or|otherwise|or else) [to] "
        "{rainyZone} [<if_rainy>]",
        "{robot} (deliver|go|drive) to {rainyZone} <if_rainy> (and|or|otherwise|or else) [to] "
        "{sunnyZone} [<if_sunny>]",
        "{robot} <if_sunny> (go|deliver|drive) to {sunnyZone} [and|but] <if_rainy> (go|deliver|"
        "drive) to {rainyZone}",
        "{robot} <if_rainy> (go|deliver|drive) to {rainyZone} [and|but] <if_sunny> (go|deliver|"
        "drive) to {sunnyZone}",
        "<ask> <if_sunny> (send|take) {robot} to {sunnyZone} (and|but|otherwise|or else) "
        "[<if_rainy>] to {rainyZone}",
        "{robot} (sunny|sunshine) (means|is) {sunnyZone} (and|but) (rainy|rain) (means|is) "
        "{rainyZone} [so] [go|deliver|go deliver]",
        "{robot} (check|find out|ask about) the weather (and|then) (deliver|go) to {sunnyZone} "
        "<if_sunny> (or|and) {rainyZone} <if_rainy>",
        "<ask> (have|let) {robot} (deliver|go) to [either] {sunnyZone} or {rainyZone} "
        "<weather_basis>",
        "{robot} (deliver|go) to [either] {sunnyZone} or {rainyZone} <weather_basis>",
        "{robot} [(check|look up) the weather and deliver] (sunny|if sunny|sunshine) "
        "{sunnyZone} (rainy|if rainy|rain) {rainyZone}",
        "{robot} (deliver|go) to {sunnyZone} (on|in|for) (sunny|a sunny day|sunny weather) and "
        "[to] {rainyZone} (on|in|for) (rainy|a rainy day|rainy weather)",
        # One side of the rule said ("deliver to zone c if it's raining").
        "[<ask>] {robot} (deliver|go|take the package) to {sunnyZone} <if_sunny>",
        "[<ask>] {robot} (deliver|go|take the package) to {rainyZone} <if_rainy>",
        "{robot} <if_sunny> (deliver|go|take the package) to {sunnyZone}",
        "{robot} <if_rainy> (deliver|go|take the package) to {rainyZone}",
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
    essentials=(
        "{firstRobot} deliver to {firstZone} then {secondRobot} deliver to {secondZone}",
        "have {firstRobot} deliver to {firstZone} and then {secondRobot} deliver to {secondZone}",
    ),
    templates=(
        "<ask> (have|let) {firstRobot} deliver [<cargo>] to {firstZone} (and then|then|and after "
        "that|after that|followed by) {secondRobot} [deliver|delivers] [<cargo>] to {secondZone}",
        "{firstRobot} (delivers|deliver|goes) [first] to {firstZone} (then|and then|after that) "
        "{secondRobot} [delivers|goes] to {secondZone}",
        "first {firstRobot} (delivers|deliver|goes) to {firstZone} (then|and then|next) "
        "{secondRobot} [delivers|goes] to {secondZone}",
        "<ask> (have|let) {secondRobot} deliver [<cargo>] to {secondZone} (after|once|when) "
        "{firstRobot} (delivers|has delivered|is done|finishes|is finished) [to {firstZone}]",
        "{secondRobot} (delivers|should deliver|goes) to {secondZone} (after|once) {firstRobot} "
        "(delivers|has delivered|is done) [to {firstZone}]",
        "<ask> (have|let) {firstRobot} and {secondRobot} deliver [<cargo>] to {firstZone} (one "
        "after the other|in sequence|in turn|in order|sequentially|back to back)",
        "{firstRobot} and (then|after that) {secondRobot} (deliver|go) to {firstZone}",
        "<ask> (do|run|start|make|coordinate) a (sequential|sequenced|coordinated|staggered) "
        "delivery (with|using|between) {firstRobot} and {secondRobot} [to {firstZone}]",
        "<ask> (have|tell|ask|get) {firstRobot} to (coordinate|work|sync up) with {secondRobot} "
        "[to deliver to {firstZone}|on the delivery|on a sequential delivery]",
        "<ask> (have|let) {firstRobot} (coordinate|work together|team up) with {secondRobot} "
        "[to deliver to {firstZone}|on the delivery]",
        "{firstRobot} first then {secondRobot} [to {firstZone}|deliver to {firstZone}]",
        "<ask> (deliver|bring|take) <cargo> to {firstZone} with {firstRobot} (first and then|and "
        "then|then|followed by) {secondRobot}",
        "<ask> (let|have) {firstRobot} deliver first and {secondRobot} (second|next|after|"
        "afterwards) [to {firstZone}]",
        "{firstRobot} (delivers|goes) first (then|and then|followed by) {secondRobot}",
        "<ask> (sequential|sequenced|coordinated) delivery (to|at) {firstZone} [and {secondZone}]",
        "<ask> take turns delivering to {firstZone} [and {secondZone}]",
        "<ask> deliver to {firstZone} and {secondZone} one after the other",
        "<ask> (start|begin|do|run) a (sequential|sequenced|coordinated) delivery (with|using) "
        "{firstRobot}",
        "<ask> (start|do|run|begin) a (sequential|sequenced|coordinated) delivery <end>",
        "<ask> (deliver|do the deliveries) one after the other <end>",
        "<ask> (have|let) {secondRobot} wait (for|until) {firstRobot} (delivers|has delivered|is "
        "done) (and then|then|before it) (deliver|delivers) to {secondZone}",
    ),
)

STATUS = IntentSpec(
    name="StatusIntent",
    slots=(ROBOT,),
    essentials=(
        "where is {robot}",
        "where are the robots",
        "what are the robots doing",
        "is {robot} done delivering",
        "has {robot} finished delivering",
        "is {robot} done",
        "did {robot} deliver the package",
    ),
    templates=(
        "[so|um|okay|hey] (where is|where's) {robot} [right now|now|at the moment|at]",
        "[so|um|okay|hey] (what is|what's) {robot} (doing|up to) [right now|now|at the moment]",
        "(how is|how's) {robot} (doing|getting on|coming along|going)",
        "<ask> (give me|tell me) the (status|state|location|position) of {robot}",
        "(what's|what is) the (status|state|location|position) of {robot}",
        "{robot} (status|location|position)",
        "[<ask>] (check on|update me on|give me an update on|report on) {robot}",
        "(is|has) {robot} (done|finished|there yet|busy|idle|moving|loaded|arrived|delivered|"
        "still moving|stuck) [yet]",
        "(where are {robot}|what are {robot} (doing|up to)) [right now|now]",
        "(where are the robots|what are the robots (doing|up to)) [right now|now]",
        "(where are they|what are they (doing|up to)) [right now]",
        "[<ask>] (give me|tell me|i want|i'd like) a (status|progress) (report|update)",
        "[what's the|what is the] (fleet|robot) status",
        "how are the robots (doing|getting on|coming along)",
        "[<ask>] (status|progress) report [please]",
        "(what's|what is) (happening|going on) with {robot}",
        "(did|has) {robot} (arrive|make it|deliver|get there) [yet]",
        "(is|are) {robot} still (moving|driving|going|working|busy|on (its|the|their) way)",
        "{robot} where are you [now|right now|at the moment]",
        "(which|what) zone is {robot} (in|at) [now|right now]",
        "how far (along|away) is {robot}",
        "(any|is there any) (news|update|word) (on|about|from) {robot}",
        "is (anyone|anybody|any robot|a robot) still (moving|driving|working|out)",
        "(did|has) {robot} [already] (deliver|delivered|drop off|dropped off) (its|the|a|his|her) "
        "(package|parcel|box|load) [yet|already]",
        "where (have|has) {robot} (got|gotten|ended up) [to]",
        "(is|has) {robot} (done|finished) (delivering|with the delivery|with its delivery|with its "
        "job|with the package) [yet]",
        "(has|did) {robot} (finish|finished|complete|completed) (delivering|the delivery|its "
        "delivery|its job|its task) [yet]",
    ),
)

# The follow-up to a large fleet's status summary: the robots in trouble by name
# (lambda/skill/handlers/status.py).
PROBLEM_ROBOTS = IntentSpec(
    name="ProblemRobotsIntent",
    essentials=(
        "which robots are stuck",
        "which robots have failed",
        "which robots are offline",
        "are any robots stuck",
    ),
    templates=(
        "[so|um|okay] (which|what) (robots|bots|ones) (are|got) (stuck|in trouble|offline|down|"
        "broken|having problems|having trouble) [right now|now]",
        "[so|um|okay] (which|what) (robots|bots|ones) (have failed|failed|need help|need attention|"
        "have problems|have a problem|are not working|aren't working)",
        "are (any|some) (robots|bots|of the robots|of them) (stuck|offline|down|broken|in trouble|"
        "having problems) [right now|now]",
        "is (any robot|any of the robots|any of them) (stuck|offline|down|broken|in trouble)",
        "(have any robots|have any of the robots|has any robot|did any robot) failed",
        "[<ask>] (tell me|list|name) the (stuck|failed|offline|broken) robots",
        "(which robot is|which one is|which ones are) (stuck|offline|broken)",
        "(any|are there any) (problems|trouble|issues) with the robots [right now]",
        "(any|are there any) (stuck|failed|offline|broken) robots [right now]",
        "(which|what) robots (need|still need) (help|attention|rescuing) [right now|now]",
    ),
)

EMERGENCY_STOP = IntentSpec(
    name="EmergencyStopIntent",
    slots=(ROBOT,),
    commands_robots=True,
    essentials=("emergency stop", "stop {robot}"),
    templates=(
        "emergency stop [{robot}|for {robot}|everything|now]",
        "(hit|press|pull) the (emergency stop|e stop|kill switch) [now]",
        "(stop|halt|freeze|abort) {robot} [now|immediately|right now|at once|right away]",
        "{robot} (stop|halt|freeze|stop moving|stand still|hold still|stop right there|stop now|"
        "stay where you are|don't move)",
        "(tell|make|get) {robot} [to] (stop|halt|freeze|stop moving|stand still)",
        "(stop|halt|freeze|kill) all (motion|movement|robot motion)",
        "(stop|halt|freeze|abort) (everything|it all|the mission|the task) [now|right now]",
        "(stop|halt) (stop|halt) [stop|halt]",
        "(whoa|woah|wait) (stop|halt) {robot}",
        "(abort|cancel) (the|that) (command|move|delivery|task) for {robot}",
        "(emergency|urgent) (halt|freeze|shutdown) [now]",
        "{robot} (abort|cancel) (that|the task|the delivery|the move)",
        "(hold it|hold on|wait) {robot} (don't move|stop|stay there|freeze|stay put)",
        "(stop|halt|freeze) {robot} (please|thanks|for me)",
    ),
)

WEATHER = IntentSpec(
    name="WeatherIntent",
    # The robots' own question (vahr.domain.invocation.WEATHER_QUESTION) and its variants.
    essentials=("what is the weather", "what the weather is", "tell me what the weather is"),
    templates=(
        "[so|um|okay|hey] (what is|what's) the weather [like] [today|now|right now|outside|at the "
        "moment|for the experiment|in the experiment]",
        "[so|um|okay] (how is|how's) the weather [today|outside|now]",
        "[<ask>] (tell|give) me the weather [today|now|please]",
        "is it (sunny|rainy|raining|going to rain|nice out|sunny or rainy|sunny outside|wet "
        "outside|dry) [today|now|outside]",
        "(what's|what is) the (forecast|weather report|weather forecast) [today|for today]",
        "[<ask>] weather (report|update|please|check)",
        "(what|how) the weather is [like] [today]",
        "[<ask>] (tell me|let me know) what the weather is [like] [today]",
        "(will|does) it rain today",
        "(is the weather|is it) (good|bad|nice) [today|outside]",
        "(what's|what is) it like outside",
        "[<ask>] (check|look up) the weather [for me]",
        "do (i|we) need (an umbrella|sunglasses|a jacket|a coat|a raincoat) [today|now|outside]",
        "[<ask>] (tell me|let me know) if it's (raining|sunny|rainy|going to rain)",
        "(do we have|is there|will there be|are we getting) (rain|sun|sunshine) [or (sun|rain)] "
        "[today|now]",
        "(how's|how is|what's) the weather for the (task|experiment|delivery|run)",
        "[the|today's] weather [please|now|today|report please]",
        "[<ask>] (give me|get me|i want|i'd like|i need) the weather [please|now|today]",
        "(ask|check) (for|about|on) the weather [please|now|today]",
    ),
)

# A correction of the last command ("no, zone b", "I meant placebot two", "not that
# robot"): the skill sends it again to the robot or zone named (lambda/skill/handlers/
# correction.py). Nothing named means the robot was wrong.
CORRECTION = IntentSpec(
    name="CorrectionIntent",
    slots=(ROBOT, ZONE),
    essentials=(
        "no {zone}",
        "no i meant {zone}",
        "i meant {robot}",
        "not that robot",
        "wrong robot",
    ),
    templates=(
        "(no|nope|no no|oh no|no wait|wait|correction) [i meant|i said] {zone} [instead|please]",
        "(no|nope|no no|no wait|wait|correction) [i meant|i said] {robot} [instead|please]",
        "i meant {robot} [instead|please]",
        "i meant {zone} [instead|please]",
        "(wrong zone|not that zone|that's the wrong zone) [i meant] {zone}",
        "(wrong robot|not that robot|that's the wrong robot) [i meant] {robot}",
        "{zone} instead [please]",
        "{robot} instead [please]",
        "(actually|no actually) [i meant] {zone} instead",
        "no i meant {robot} (to|in|at) {zone}",
        "(not that robot|wrong robot|that's the wrong robot|not this robot|you sent the wrong "
        "robot|the wrong robot) [please]",
        "no (not that robot|wrong robot|the wrong robot)",
    ),
)

# "Cancel that", "undo": stop the robot the last command went to, only it.
# (AMAZON.CancelIntent keeps "cancel" alone: it ends the session and the robots carry on.)
UNDO = IntentSpec(
    name="UndoIntent",
    essentials=("cancel that", "undo", "undo that", "scratch that"),
    templates=(
        "[no|wait|oops] (cancel|undo|scrap|scratch|call off) (that|the last command|the last "
        "one|my last command|what i just said|that command|that order|that last command) "
        "[please|now]",
        "[no|wait|oops] (undo|undo it|forget that|ignore that|ignore what i just said|take that "
        "back|belay that|disregard that|strike that) [please]",
        "i (didn't|did not) mean (that|it) [cancel it|undo it]",
        "(that was|that's) a mistake (cancel|undo) (it|that)",
        "(don't|do not) go there [after all]",
    ),
)


# Fleet dispatch: tasks without a robot's name (docs/dispatch.md). A robot-less delivery
# ("deliver a package to zone c") stays DeliverIntent; its handler gives it to the fleet.
COUNT = SlotSpec("count", COUNT_TYPE)
GROUP = SlotSpec("group", GROUP_TYPE)
ORIGIN = SlotSpec("origin", ZONE_TYPE)

FLEET_NAVIGATE = IntentSpec(
    name="FleetNavigateIntent",
    slots=(ZONE, COUNT, GROUP),
    commands_robots=True,
    essentials=(
        "send a robot to {zone}",
        "send {count} robots to {zone}",
        "send {group} to {zone}",
    ),
    templates=(
        # Not "move a robot": "move" names the robot it moves ("move placebot one"), and a
        # misheard name before "robot" must stay NavigateIntent's question, not a dispatch.
        "<ask> (send|dispatch|get|bring) (a|any) (robot|bot|free robot|available robot|spare "
        "robot) <way> <to> {zone} <end>",
        "<ask> (send|move|dispatch|get|bring) {count} (robots|bots|free robots|available robots) "
        "<way> <to> {zone} <end>",
        "(i need|i want|i'd like|we need|get me) (a|any|one) (robot|free robot|bot) (in|at|over "
        "at) {zone} <end>",
        "(i need|i want|i'd like|we need|get me) {count} (robots|free robots|bots) (in|at|over "
        "at) {zone} <end>",
        "<ask> (send|move|dispatch|get) {group} <way> <to> {zone} <end>",
        "<ask> (have|let|make|tell) {group} <go> <way> <to> {zone} <end>",
        "{group} (please|should|need to|can) <go> <way> <to> {zone} <end>",
    ),
)

# The robots reported in one zone, sent to another. An intent of its own, as its two ZONE
# slots come in this order in every sample.
ZONE_ROBOTS = IntentSpec(
    name="ZoneRobotsIntent",
    slots=(ORIGIN, ZONE),
    commands_robots=True,
    essentials=("send the robots in {origin} to {zone}",),
    templates=(
        "<ask> (send|bring|take|get) the robots (in|at|that are in|sitting in|waiting in) "
        "{origin} <way> <to> {zone} <end>",
        "<ask> (have|let|make) the robots (in|at) {origin} <go> <way> <to> {zone} <end>",
        "{origin} (robots|bots) (please|should|can) <go> <way> <to> {zone} <end>",
        "<ask> (whoever|whichever robots|any robots) (is|are) (in|at) {origin} (should|can) <go> "
        "<way> <to> {zone}",
        "<ask> (clear|empty) {origin} (and|by) (send|sending|move|moving) (the|its|all the) "
        "robots <to> {zone}",
        "(every|each) robot (in|at) {origin} (should|must|can) <go> <way> <to> {zone} <end>",
    ),
)

IDLE_ROBOTS = IntentSpec(
    name="IdleRobotsIntent",
    slots=(ZONE,),
    commands_robots=True,
    essentials=("send every idle robot to {zone}", "send the idle robots to {zone}"),
    templates=(
        "<ask> (send|move|dispatch|get|bring|take) (every|each|any|all) (idle|free|available|"
        "unused|waiting) (robot|robots|bot|bots) <way> <to> {zone} <end>",
        "<ask> (send|move|dispatch|get|bring|take) (the|all the|all) (idle|free|available|unused|"
        "waiting) (robots|bots) <way> <to> {zone} <end>",
        "<ask> (have|let|make) (every|each|all) (idle|free|available) (robot|robots) <go> <way> "
        "<to> {zone} <end>",
        "(every|each|all) (idle|free|available) (robot|robots) (should|must|can) <go> <way> <to> "
        "{zone} <end>",
        "<ask> (whoever|every robot that|any robot that|all robots that) (is|are) (idle|free|not "
        "busy|doing nothing) <go> <way> <to> {zone}",
        "{zone} (needs|wants|could use) (every|all the|all) (idle|free|available) (robots|bots) "
        "<end>",
    ),
)

TASK_QUEUE = IntentSpec(
    name="TaskQueueIntent",
    essentials=("what is queued", "what's in the queue", "what tasks are waiting"),
    templates=(
        "[<ask>] (what is|what's|what has been|what got) (queued|waiting|lined up|pending) "
        "[up|now|right now|for the robots]",
        "[<ask>] (what's|what is) (in|on) the (queue|task queue|waiting list|backlog) [now|right "
        "now]",
        "[<ask>] (which|what) (tasks|deliveries|jobs|orders) are (waiting|queued|pending|in line|"
        "lined up) [now|right now]",
        "[<ask>] (read|list|tell me|show me) the (queue|task queue|pending tasks|waiting tasks|"
        "backlog) [please]",
        "(is|are) (anything|any tasks|any deliveries) (queued|waiting|pending|in the queue)",
        "how many (tasks|deliveries|jobs) are (queued|waiting|pending|in the queue)",
        "(what's|what is) next (in line|in the queue|for the fleet)",
    ),
)

CANCEL_TASK = IntentSpec(
    name="CancelTaskIntent",
    slots=(ZONE,),
    essentials=("cancel the delivery to {zone}", "cancel the task to {zone}"),
    templates=(
        "[<ask>] (cancel|drop|forget|scrap|call off|remove) the (delivery|task|trip|job|order|"
        "queued delivery|queued task) (to|for|into) {zone} <end>",
        "[<ask>] (cancel|drop|forget|scrap|call off) (that|this) (delivery|task|trip) (to|for) "
        "{zone} <end>",
        "[<ask>] (never mind|forget about) the (delivery|task|trip) (to|for) {zone}",
        "[<ask>] (take|remove) the (delivery|task) (to|for) {zone} (off|out of) the (queue|list)",
        "[<ask>] (i don't need|we don't need|no more) the (delivery|task|trip) (to|for) {zone} "
        "[anymore]",
    ),
)

# Zones closed at run time (docs/floors.md): no robot is sent into a closed zone.
CLOSE_ZONE = IntentSpec(
    name="CloseZoneIntent",
    slots=(ZONE,),
    essentials=("close {zone}", "block {zone}"),
    templates=(
        "[<ask>] (close|shut|block|block off|close off|seal off|lock down|cordon off|fence off) "
        "{zone} <end>",
        "[<ask>] (close|shut|block) {zone} (for now|until further notice|to the robots|to all "
        "robots|for the robots)",
        "[<ask>] (mark|set) {zone} (as closed|as blocked|as off limits)",
    ),
)

OPEN_ZONE = IntentSpec(
    name="OpenZoneIntent",
    slots=(ZONE,),
    essentials=("open {zone}", "reopen {zone}"),
    templates=(
        "[<ask>] (open|reopen|unblock|open up) {zone} [again] <end>",
        "[<ask>] (open|reopen|unblock) {zone} (again|to the robots|for the robots|to all robots)",
        "[<ask>] (mark|set) {zone} (as open|as open again|as clear)",
    ),
)

# Batteries and service (docs/dispatch.md): the charge of a robot or of the fleet, a robot
# sent to charge now, and robots taken out of service and put back.
PERCENT = SlotSpec("percent", PERCENT_TYPE)
# Fewer samples than the others: the model's samples are bounded in all (generator.py), and
# so are the sentences the station hears with a thousand robots' names (vahr.station).
BATTERY_SAMPLES = 60

BATTERY = IntentSpec(
    name="BatteryIntent",
    max_samples=BATTERY_SAMPLES,
    slots=(ROBOT, PERCENT),
    essentials=(
        "how much battery does {robot} have",
        "which robots are below {percent} percent",
        "which robots are low on battery",
        "what is the battery of {robot}",
    ),
    templates=(
        "[<ask>] how much (battery|charge|power|juice) (does|has) {robot} (have|got|left) [left]",
        "[<ask>] (what is|what's|tell me) the (battery|charge|battery level|charge level) of "
        "{robot} [now|right now]",
        "[<ask>] how (charged|full) is {robot} [now|right now]",
        "[<ask>] (is|does) {robot} (low on battery|need to charge|need charging|running low)",
        "[<ask>] (which|what) (robots|bots|ones) (are|have) (below|under|less than|lower than) "
        "{percent} percent [battery|charge]",
        "[<ask>] (which|what) (robots|bots|ones) (are|have) (below|under|less than) {percent} "
        "percent (of battery|of charge|left)",
        "(are|is) (any|some) (robots|bots|of the robots) (below|under) {percent} percent",
        "[<ask>] (which|what) (robots|bots|ones) (are|run) (low on|short of) (battery|charge|"
        "power)",
        "[<ask>] (which|what) (robots|bots|ones) need (to charge|charging|a charge)",
        "[<ask>] (how much battery|how much charge|what charge) do {robot} have",
        "[<ask>] (what are|tell me) the battery levels [of the robots|of the fleet]",
    ),
)

CHARGE = IntentSpec(
    name="ChargeIntent",
    max_samples=BATTERY_SAMPLES,
    slots=(ROBOT,),
    commands_robots=True,
    essentials=(
        "send {robot} to charge",
        "charge {robot}",
        "{robot} go charge",
    ),
    templates=(
        "<ask> (send|take|bring|get) {robot} (to charge|to recharge|charging|to get charged|to "
        "its charger|to a charger|to the nearest charger) [now|right now] <end>",
        "<ask> (charge|recharge|plug in|dock) {robot} [now|right now] <end>",
        "{robot} (go|should go|must go|needs to go) (charge|recharge|and charge|charging|to a "
        "charger|to charge) [now|right now]",
        "{robot} (needs|has) to (charge|recharge|be charged) [now|right now]",
        "<ask> (have|let|make) {robot} (charge|recharge|go charge|go and charge|dock) [now|right "
        "now]",
        "<ask> (put|set) {robot} (on charge|on the charger|on a charger) [now|right now]",
    ),
)

OUT_OF_SERVICE = IntentSpec(
    name="OutOfServiceIntent",
    max_samples=BATTERY_SAMPLES,
    slots=(ROBOT, GROUP),
    essentials=(
        "take {robot} out of service",
        "take {group} out of service",
        "put {robot} out of service",
    ),
    templates=(
        "<ask> (take|put|pull|set) {robot} out of (service|operation|rotation|the pool) "
        "[for maintenance|for repairs|for now] <end>",
        "<ask> (take|put|pull|set) {group} out of (service|operation|rotation|the pool) "
        "[for maintenance|for repairs|for now] <end>",
        "{robot} is (out of service|out of order|down for maintenance|in maintenance) [now]",
        "{group} are (out of service|out of order|down for maintenance|in maintenance) [now]",
        "<ask> (mark|set) {robot} (as out of service|as out of order|as in maintenance)",
        "<ask> (mark|set) {group} (as out of service|as out of order|as in maintenance)",
        "<ask> (stop giving|don't give|give no) (tasks|jobs|work) to {robot} [for now]",
        "<ask> (retire|withdraw|bench) {robot} [for maintenance|for now]",
    ),
)

BACK_IN_SERVICE = IntentSpec(
    name="BackInServiceIntent",
    max_samples=BATTERY_SAMPLES,
    slots=(ROBOT, GROUP),
    essentials=(
        "put {robot} back in service",
        "put {group} back in service",
        "{robot} is back in service",
    ),
    templates=(
        "<ask> (put|bring|take|set) {robot} back (in|into|to) (service|operation|rotation|the "
        "pool) <end>",
        "<ask> (put|bring|take|set) {group} back (in|into|to) (service|operation|rotation|the "
        "pool) <end>",
        # Not "return X to ...": a robot returns to a zone ("placebot two return to the
        # loading zone" is a navigation).
        "<ask> restore {robot} to (service|operation) <end>",
        "<ask> restore {group} to (service|operation) <end>",
        "{robot} is (back in service|back in operation|repaired|fixed|working again) [now]",
        "{group} are (back in service|back in operation|repaired|fixed|working again) [now]",
        "<ask> (mark|set) {robot} (as in service|as back in service|as working)",
        "<ask> (give|start giving) (tasks|jobs|work) to {robot} again",
    ),
)


CUSTOM_INTENTS: tuple[IntentSpec, ...] = (
    NAVIGATE,
    DELIVER,
    WEATHER_DELIVERY,
    SEQUENTIAL_DELIVERY,
    STATUS,
    PROBLEM_ROBOTS,
    EMERGENCY_STOP,
    WEATHER,
    CORRECTION,
    UNDO,
    FLEET_NAVIGATE,
    ZONE_ROBOTS,
    IDLE_ROBOTS,
    TASK_QUEUE,
    CANCEL_TASK,
    CLOSE_ZONE,
    OPEN_ZONE,
    BATTERY,
    CHARGE,
    OUT_OF_SERVICE,
    BACK_IN_SERVICE,
)

BUILT_IN_INTENTS: tuple[str, ...] = (
    "AMAZON.HelpIntent",
    "AMAZON.CancelIntent",
    "AMAZON.StopIntent",
    "AMAZON.NavigateHomeIntent",
    FALLBACK_INTENT,
)
