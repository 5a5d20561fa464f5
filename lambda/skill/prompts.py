"""Every sentence the skill speaks, as data. Placeholders are filled with `str.format`.

Robot names come from fleet.yaml (their first spoken name) and zone names from
`skill.vocabulary`; the code that picks a sentence never spells one out itself.
"""

from __future__ import annotations

import sys

from skill.catalog import localise
from vahr.domain.invocation import INVOCATION_NAME
from vahr.domain.weather import WEATHERS

SKILL_NAME = INVOCATION_NAME

WELCOME = (
    f"Welcome to {SKILL_NAME}. You can send a robot to a zone, have it deliver a package, "
    "ask where the robots are, or say emergency stop. What would you like to do?"
)
WELCOME_REPROMPT = "For example, say: send {robot} to {zone}. What would you like to do?"
HELP = (
    "You can say: send {robot} to {zone}; have {robot} deliver a package to {zone}; "
    "have {robot} deliver based on the weather; {robot} deliver to {zone} then {other} "
    "deliver to {other_zone}; where are the robots; or emergency stop. "
    "What would you like to do?"
)
HELP_REPROMPT = "What would you like the robots to do?"
NEXT = "What else would you like the robots to do?"
GOODBYE = "Goodbye."
GOODBYE_ROBOTS_KEEP_GOING = "Goodbye. The robots carry on; to halt them, say emergency stop."
FALLBACK_SPEECH = (
    f"Sorry, {SKILL_NAME} can't help with that. I sent nothing to the robots. "
    "You can say: send {robot} to {zone}, or: where are the robots?"
)
FALLBACK_REPROMPT = "What would you like the robots to do?"

# Elicitation: the choices are listed so the person knows what they can say.
ASK_ROBOT = "Which robot: {choices}?"
# The last choice when a large fleet's robots are too many to list (skill.vocabulary).
ANOTHER_ROBOT = "another of the {count} robots by its name"
ASK_FIRST_ROBOT = "Which robot delivers first: {choices}?"
ASK_SECOND_ROBOT = "Which robot delivers second: {choices}?"
ASK_ZONE = "To which zone: {choices}?"
ASK_DELIVERY_ZONE = "Where should {robot} deliver the package: {choices}?"
LOADING_IS_NOT_A_DESTINATION = "Packages are picked up in the loading zone. "
ASK_FIRST_ZONE = "Where does {robot} deliver: {choices}?"
ASK_SECOND_ZONE = "Where does {robot} deliver: {choices}?"
UNKNOWN_ROBOT = "I don't know a robot called {heard}. "
UNKNOWN_ZONE = "I don't know a zone called {heard}. "
NEEDS_ONE_ROBOT = "A sequential delivery needs one robot at a time. "
SAME_ROBOT = "{robot} already delivers first. "
OTHER_WEATHER_RULE = (
    "Weather deliveries always go to {sunny} when it is sunny and {rainy} when it is rainy, "
    "so I sent no robot. For that rule, say: have {robot} deliver based on the weather."
)
# A value heard several ways is asked about by name: "Zone B or zone D?".
ASK_WHICH_OF = "{choices}?"
# Letters that sound alike (B, C, D) are told apart by their spelling-alphabet words, which
# the question then offers: "Zone B or zone D? You can also say bravo or delta."
SPELLED_CHOICES = "You can also say {choices}."
GIVE_UP = (
    "Sorry, I still did not get that, so I sent nothing. Try, for example: send {robot} to {zone}."
)

# Acknowledged commands, by action. {robot} is capitalised when it starts the sentence.
ACKNOWLEDGED = {
    "navigate": "{robot} is on its way to {zone}.",
    "deliver": "{robot} is on its way to pick up a package for {zone}.",
    "weather_delivery": "{robot} will ask me about the weather and deliver accordingly.",
    "sequential_delivery": "{robot} will deliver to {zone} first.",
    "sequential_delivery_after": "{robot} will deliver to {zone} once {after} has delivered.",
    "stop": "{robot} has stopped.",
    "ping": "{robot} is listening.",
}
FLEET_ACKNOWLEDGED = {
    "navigate": "{robots} are on their way to {zone}.",
    "deliver": "{robots} are on their way to pick up packages for {zone}.",
    "weather_delivery": "{robots} will ask me about the weather and deliver accordingly.",
    "sequential_delivery": "{robots} will deliver to {zone}.",
    "stop": "{robots} have stopped.",
    "ping": "{robots} are listening.",
}
BOTH_ROBOTS = "Both robots"
ALL_ROBOTS = "All {count} robots"
SEQUENTIAL_ACKNOWLEDGED = (
    "{first} will deliver to {first_zone}, then {second} will deliver to {second_zone}."
)
SEQUENTIAL_PARTIAL = "Only part of the sequential delivery was confirmed: "

# Robots that did not acknowledge.
REJECTED = "{robot} refused the command: {reason}."
FAILED = "{robot} could not do it: {reason}."
CANCELLED = "{robot} cancelled the command at once."
OFFLINE = "I sent the command, but {robot} seems to be offline."
NOT_CONFIRMED = "I sent the command, but {robot} did not confirm it in time."
FLEET_PARTIAL = "{confirmed} of {count} robots confirmed; {problems}."
FLEET_NONE = "None of the {count} robots confirmed; {problems}."
PROBLEM_REJECTED = "{robot} refused: {reason}"
PROBLEM_FAILED = "{robot} failed: {reason}"
PROBLEM_CANCELLED = "{robot} cancelled it"
PROBLEM_OFFLINE = "{robot} did not answer and seems to be offline"
# Not "did not answer": a robot may answer a moment after the skill stopped waiting.
PROBLEM_SILENT = "{robot} had not answered yet"
NO_REASON = "no reason given"

# Status, one sentence per robot.
STATUS_NEVER_REPORTED = "{robot} has not reported yet."
STATUS_OFFLINE = "{robot} seems to be offline."
STATUS_OFFLINE_LAST_SEEN = "{robot} seems to be offline; it was last seen in {zone}."
STATUS_OFFLINE_LAST_SEEN_NEAR = "{robot} seems to be offline; it was last seen near {zone}."
STATUS_IDLE_IN = "{robot} is idle in {zone}."
# Between zones: the nearest zone to the robot's reported pose.
STATUS_IDLE_NEAR = "{robot} is idle near {zone}."
STATUS_IDLE = "{robot} is idle."
STATUS_CARRYING = "{robot} is carrying a package to {zone}."
STATUS_FETCHING = "{robot} is on its way to the loading zone to pick up a package."
STATUS_FETCHING_FOR = "{robot} is on its way to pick up a package for {zone}."
STATUS_MOVING_TO = "{robot} is on its way to {zone}."
STATUS_MOVING = "{robot} is moving."
STATUS_LOADING = "{robot} is being loaded in {zone}."
STATUS_UNLOADING = "{robot} is being unloaded in {zone}."
STATUS_WAITING_WEATHER = "{robot} is waiting to hear the weather."
STATUS_WAITING_TURN = "{robot} is waiting for its turn to deliver to {zone}."
STATUS_WAITING = "{robot} is waiting."
STATUS_STOPPED_IN = "{robot} is stopped in {zone}."
STATUS_STOPPED_NEAR = "{robot} is stopped near {zone}."
STATUS_STOPPED = "{robot} is stopped."
STATUS_STUCK_TO = "{robot} is stuck on its way to {zone}."
STATUS_STUCK_NEAR = "{robot} is stuck near {zone}."
STATUS_STUCK = "{robot} is stuck."
STATUS_ERROR_REASON = "{robot} has a problem: {reason}."
STATUS_ERROR = "{robot} has a problem."
STATUS_UNREADABLE = "I could not read the state of {robot}."

# Status of a large fleet (skill.speech.fleet_summary): the counts by status, then the
# robots that need attention by name and place. Each count as (one robot, several robots).
SUMMARY_OPENING = "Of {total} robots, {counts}"
SUMMARY_COUNTS = {
    "idle": ("{n} is idle", "{n} are idle"),
    "navigating": ("{n} is driving", "{n} are driving"),
    "loading": ("{n} is being loaded", "{n} are being loaded"),
    "unloading": ("{n} is being unloaded", "{n} are being unloaded"),
    "waiting": ("{n} is waiting", "{n} are waiting"),
    "stopped": ("{n} is stopped", "{n} are stopped"),
    "stuck": ("{n} is stuck", "{n} are stuck"),
    "error": ("{n} has failed", "{n} have failed"),
    "offline": ("{n} is offline", "{n} are offline"),
    "unreported": ("{n} has not reported", "{n} have not reported"),
}
SUMMARY_IN = "{robot} in {zone}"
SUMMARY_NEAR = "{robot} near {zone}"
SUMMARY_MORE = "{n} more"
# Before the named robots when a trouble is not the last count of the opening.
SUMMARY_LABELS = {"stuck": "Stuck", "error": "Failed", "offline": "Offline"}
# "Which robots are stuck?": each trouble as (one robot, several robots).
PROBLEMS = {
    "stuck": ("{n} robot is stuck", "{n} robots are stuck"),
    "error": ("{n} robot has failed", "{n} robots have failed"),
    "offline": ("{n} robot is offline", "{n} robots are offline"),
}
PROBLEMS_NONE = "No robot is stuck, failed or offline."
INDEX_UNAVAILABLE = "Sorry, I could not count the robots just now. Please try again in a moment."
FLEET_PROBLEMS_MORE = "and {n} more had not confirmed yet"

# The experiment's weather. The robots recognise these exact openings.
WEATHER = {weather: f"The weather is {weather}." for weather in WEATHERS}

# Errors, spoken by the catch-all exception handler.
GATEWAY_ERROR = "Sorry, I could not reach the robots just now. Please try again in a moment."
GENERIC_ERROR = "Sorry, something went wrong on my side. Please try again."
# A request from a skill this function does not serve (skill.skill_gate).
NOT_THIS_SKILL = (
    "Sorry, this skill is not set up to take requests here, so I sent nothing to the robots."
)
ERROR_REPROMPT = "What would you like the robots to do?"

# Corrections and undo of the last command ("no, zone b", "I meant placebot two", "cancel
# that"). The report of what the robots did follows the first sentence.
CORRECTED = "Okay, not {old}. "
ALREADY_SO = "{robot} is already on that command; I changed nothing."
NOTHING_TO_CORRECT = "There is no command of mine to correct, so I changed nothing."
NOTHING_TO_UNDO = (
    "There is no command of mine to cancel, so I changed nothing. "
    "To halt every robot, say emergency stop."
)
UNDONE = "Okay, I cancelled that. "
ASK_CORRECT_ROBOT = "Which robot did you mean: {choices}?"
CONFIRM_OTHER_ROBOT = "{robot} instead?"
WEATHER_HAS_NO_ZONE = (
    "{robot} delivers where the weather says, so there is no zone to change; I changed nothing."
)
INTENT_DENIED = "Okay, I sent nothing. Please say it again."

# Fleet dispatch (skill.handlers.fleet_tasks, skill.task_speech): tasks without a robot's name.
TASK_NAMES = {
    "navigate": "the trip to {zone}",
    "deliver": "the delivery to {zone}",
    "charge": "charging at {zone}",
}
TASK_NAMES_PLURAL = {
    "navigate": "trips to {zone}",
    "deliver": "deliveries to {zone}",
    "charge": "charges at {zone}",
}
DISPATCHED = {
    "navigate": "{robot} is on its way to {zone}.",
    "deliver": "{robot} is on its way to pick up a package for {zone}.",
}
DISPATCHED_MANY = {
    "navigate": "{robots} are on their way to {zone}.",
    "deliver": "{robots} are on their way to pick up packages for {zone}.",
}
ALL_BUSY = "All robots are busy; {task} is {place} in line."
ALL_BUSY_MANY = "All robots are busy; {count} {tasks} are queued, the first {place} in line."
QUEUED_REST = {
    1: "No other robot is free, so one more waits, {place} in line.",
    2: "No other robot is free, so {count} more wait, from {place} in line.",
}
MEMBERS_BUSY = "{robots} {verb} busy and will go when free."
ORDINALS = (
    "first",
    "second",
    "third",
    "fourth",
    "fifth",
    "sixth",
    "seventh",
    "eighth",
    "ninth",
    "tenth",
)
ORDINAL_BEYOND = "number {n}"
QUEUE_EMPTY = "Nothing is queued."
QUEUE_LISTED = {1: "One task is queued: {tasks}.", 2: "{count} tasks are queued: {tasks}."}
QUEUE_ENTRY = "{place}, {task}"
QUEUE_MORE = "and {count} more"
CANCELLED_QUEUED = "I cancelled {task}, which was {place} in line."
CANCELLED_HELD = "I cancelled {task} and stopped {robot}."
CANCELLED_MANY = "I cancelled the {count} tasks to {zone}."
CANCELLED_MANY_STOPPED = "I cancelled the {count} tasks to {zone} and stopped {robots}."
NOTHING_TO_CANCEL = "There is no task to {zone} to cancel."
NO_DISPATCHER = (
    "Sending a robot without its name needs the fleet dispatcher, which is not running here, "
    "so I sent no robot."
)
UNKNOWN_GROUP = "I don't know a group called {heard}; the groups are {choices}."
NO_GROUPS = "I don't know a group called {heard}; this fleet has no groups."
TOO_MANY = "{owner} has {most} robots, so I cannot send {count}."
NO_ROBOT_IN_ZONE = "No free robot is in {zone}, so I sent none."
NO_IDLE_ROBOT = "No robot is idle just now, so I sent none."
NO_FREE_ROBOT = "No robot is free to go just now, so I sent none."
DISPATCH_REFUSED = "The dispatcher refused: {reason}."
ASK_ORIGIN = "From which zone: {choices}?"

# Zones closed at run time: "close zone b", "open zone b".
ZONE_CLOSED = "{zone} is closed, so I sent no robot there."
ZONE_NOW_CLOSED = "{zone} is closed. No robot will be sent there until it opens."
ZONE_ALREADY_CLOSED = "{zone} was already closed."
ZONE_NOW_OPEN = "{zone} is open again."
ZONE_ALREADY_OPEN = "{zone} was not closed."
# What waits for a closed zone, and what went when it opened.
ZONE_WAITING = {
    1: "One queued task to it waits until it opens.",
    2: "{count} queued tasks to it wait until it opens.",
}
ZONE_GIVEN = {
    1: "{robots} took the task that waited for it.",
    2: "{robots} took the tasks that waited for it.",
}
# A queued task to a closed zone, read out in the queue.
QUEUE_ENTRY_WAITING = "{place}, {task}, waiting until {zone} opens"
NO_ZONE_DESK = (
    "Closing a zone needs the fleet dispatcher, which is not running here, so nothing changed."
)
# Batteries: "how much battery does rover one have", "which robots are below 30 percent",
# "send rover one to charge".
BATTERY_LEVEL = "{robot} has {percent} percent battery."
BATTERY_CHARGING = "{robot} has {percent} percent battery and is charging."
BATTERY_UNKNOWN = "{robot} does not report its battery."
BATTERY_OFFLINE = "{robot} is offline; it last reported {percent} percent battery."
BATTERY_ENTRY = "{robot} {percent} percent"
BATTERY_ENTRY_CHARGING = "{robot} {percent} percent, charging"
BATTERY_BELOW_NONE = "No robot is below {percent} percent."
BATTERY_BELOW = {
    1: "One robot is below {percent} percent: {robots}.",
    2: "{count} robots are below {percent} percent: {robots}.",
}
BATTERY_FLEET = "The batteries: {robots}."
# A large fleet's batteries, counted by the fleet index: how many are under a percent and
# the lowest of them (all of them read: "the lowest"; a page of them: "among them"), and the
# whole fleet's in two counts (none, one, many).
BATTERY_BELOW_LOWEST = "{count} robots are below {percent} percent; the lowest: {robots}."
BATTERY_BELOW_AMONG = "{count} robots are below {percent} percent, among them {robots}."
BATTERY_FLEET_COUNTS = (
    "Of {total} robots, {low} and {charging}. The station shows each robot's charge."
)
BATTERY_COUNTS = {
    "low": ("none is below {percent} percent", "{n} is below {percent} percent",
            "{n} are below {percent} percent"),
    "charging": ("none is charging", "{n} is charging", "{n} are charging"),
}  # fmt: skip
CHARGE_SENT = "{robot} is on its way to {zone} to charge."
NO_CHARGER = "Every charger is taken or closed now, so {robot} stays where it is."
# Out of service: "take rover one out of service", "put rover one back in service".
OUT_OF_SERVICE_REFUSED = {
    1: "{robots} is out of service, so I sent nothing.",
    2: "{robots} are out of service, so I sent nothing.",
}
NOW_OUT_OF_SERVICE = {
    1: "{robots} is out of service now and gets no tasks.",
    2: "{robots} are out of service now and get no tasks.",
}
ALREADY_OUT_OF_SERVICE = {
    1: "{robots} was already out of service.",
    2: "{robots} were already out of service.",
}
NOW_IN_SERVICE = {
    1: "{robots} is back in service.",
    2: "{robots} are back in service.",
}
ALREADY_IN_SERVICE = {
    1: "{robots} was not out of service.",
    2: "{robots} were not out of service.",
}
SERVICE_REASSIGNED = "{task} went to {robot} instead."
SERVICE_REQUEUED = "{task} waits in the queue for another robot."
SERVICE_WAITING = {
    1: "One task only it may do waits for it.",
    2: "{count} tasks only it may do wait for it.",
}
SERVICE_GIVEN = "It took {task}."
NO_SERVICE_DESK = (
    "Taking a robot out of service needs the fleet dispatcher, which is not running here, "
    "so nothing changed."
)
# Who may do what (skill.guard). A refusal says what the person may do, and that nothing
# was sent: to someone the skill knows by name, or to someone it does not know.
REFUSED_KNOWN = "Sorry, {name}: as {role} you may {may}. I sent nothing."
REFUSED_UNKNOWN = "Sorry, I don't know who is speaking, so you may {may}. I sent nothing."
ROLE_NAMES = {"viewer": "a viewer", "operator": "an operator", "supervisor": "a supervisor"}
MAY = {
    "viewer": "ask about the robots and stop them, but not send them",
    "operator": (
        "send robots and ask about them, but commands to the whole fleet or to many robots, "
        "and service changes, need a supervisor"
    ),
    "supervisor": "do everything",
}
# A yes to a fleet-wide command from someone other than who asked for it.
NOT_YOURS_TO_CONFIRM = "Only the person who asked for that can confirm it, so I sent nothing."
PEOPLE_UNAVAILABLE = (
    "Sorry, I could not check who is speaking just now, so I sent nothing. "
    "To halt the robots, say emergency stop."
)
# Fleet-wide and disruptive commands are confirmed first, as Alexa's intent confirmation
# asks; by intent, with the slots' names filled in. {robots} is a count or a group.
CONFIRM_COMMAND = {
    "NavigateIntent": "Send {robot} to {zone}, is that right?",
    "DeliverIntent": "Have {robot} deliver packages to {zone}, is that right?",
    "WeatherDeliveryIntent": "Have {robot} deliver by the weather, is that right?",
    "FleetNavigateIntent": "Send {robots} to {zone}, is that right?",
    "IdleRobotsIntent": "Send every idle robot to {zone}, is that right?",
    "ZoneRobotsIntent": "Send the robots in {origin} to {zone}, is that right?",
    "CorrectionIntent": "Send {robot} instead, is that right?",
    "CloseZoneIntent": "Close {zone}, so that no robot goes there, is that right?",
    "OpenZoneIntent": "Open {zone} again, is that right?",
}
CONFIRM_ANY = "That affects the whole fleet. Is that right?"
ROBOTS_COUNTED = "{count} robots"
EVERY_ROBOT = "all robots"

# The word before the last of several choices ("zone a, zone b, or zone c"), and of several
# robots listed ("heron, plover and curlew").
OR = "or"
AND = "and"
# Between the thousands of a count said in digits ("1,000 robots"; skill.vocabulary.count_text).
THOUSANDS_SEPARATOR = ","

# Every other locale's sentences are vahr/domain/locales/<locale>/replies.yaml, under these
# names; the request's locale chooses (skill.catalog).
localise(sys.modules[__name__])
