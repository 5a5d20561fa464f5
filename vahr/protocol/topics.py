"""Every MQTT topic string VAHR uses, built here and nowhere else (docs/protocol.md, Topics)."""

from __future__ import annotations

import re

FLEET_CMD = "vahr/fleet/cmd"
# The zones closed now (`ZoneClosures`), retained: the dispatcher host publishes it after
# every change; robots read it (they plan around closed areas and refuse to go into one).
FLEET_ZONES = "vahr/fleet/zones"
ALL_ROBOT_CMDS = "vahr/robots/+/cmd"
ALL_EVENTS = "vahr/robots/+/events"
ALL_PRESENCE = "vahr/robots/+/presence"
ALL_SHADOW_UPDATES = "$aws/things/+/shadow/update"
ALL_SHADOW_UPDATES_ACCEPTED = "$aws/things/+/shadow/update/accepted"
# Every classic shadow's whole document after each accepted update (what the station draws).
ALL_SHADOW_DOCUMENTS = "$aws/things/+/shadow/update/documents"
# Every topic: `#` does not match topics that start with `$`, so AWS's need their own filter.
EVERY_TOPIC = "#"
EVERY_AWS_TOPIC = "$aws/#"

# Patterns, compiled on first use by re's own cache rather than at import: every Lambda
# and robot imports this module, most never parse a topic.
# AWS IoT thing names: 1-128 of letters, digits, colon, underscore and hyphen. Anything
# else (notably `/`, `+` and `#`) would change the meaning of a topic.
_THING = r"^[A-Za-z0-9:_-]{1,128}$"
_SHADOW_NAME = r"^[A-Za-z0-9:_-]{1,64}$"
_ROBOT_TOPIC = r"^vahr/robots/(?P<thing>[^/]+)/(?P<kind>cmd|events|presence)$"
_SHADOW_TOPIC = r"^\$aws/things/(?P<thing>[^/]+)/shadow/(?:name/(?P<name>[^/]+)/)?(?P<op>.+)$"

SHADOW_OPERATIONS = (
    "update",
    "update/accepted",
    "update/rejected",
    "update/delta",
    "update/documents",
    "get",
    "get/accepted",
    "get/rejected",
    "delete",
    "delete/accepted",
    "delete/rejected",
)
# What a device sends to its own shadow; the other operations are the service's answers.
SHADOW_REQUESTS = ("update", "get", "delete")
SHADOW_RESPONSES = tuple(op for op in SHADOW_OPERATIONS if op not in SHADOW_REQUESTS)


def check_thing(thing: str) -> str:
    """Return `thing` if it is a valid thing name, else raise ValueError naming the rule."""
    if not re.match(_THING, thing):
        raise ValueError(
            f"thing: {thing!r} is not a valid thing name (1-128 letters, digits, ':', '_', '-')"
        )
    return thing


def robot_cmd(thing: str) -> str:
    """Commands to one robot."""
    return f"vahr/robots/{check_thing(thing)}/cmd"


def robot_events(thing: str) -> str:
    """What one robot did (accepted, arrived, delivered...)."""
    return f"vahr/robots/{check_thing(thing)}/events"


def robot_presence(thing: str) -> str:
    """One robot's retained online/offline message (and its last will)."""
    return f"vahr/robots/{check_thing(thing)}/presence"


def shadow(thing: str, operation: str, name: str | None = None) -> str:
    """A classic (or, with `name`, named) device shadow topic, e.g. `update/accepted`."""
    if operation not in SHADOW_OPERATIONS:
        raise ValueError(f"operation: {operation!r} is not a shadow operation")
    base = f"$aws/things/{check_thing(thing)}/shadow"
    if name is not None:
        if not re.match(_SHADOW_NAME, name):
            raise ValueError(f"name: {name!r} is not a valid shadow name")
        base = f"{base}/name/{name}"
    return f"{base}/{operation}"


def shadow_request_filters() -> tuple[str, ...]:
    """The requests a shadow service answers (update, get, delete), classic and named, of
    every thing; not `shadow/#`, which would echo the service's own answers back to it."""
    return tuple(
        f"$aws/things/+/shadow/{named}{operation}"
        for named in ("", "name/+/")
        for operation in ("update", "get", "delete")
    )


def shadow_filter(thing: str = "+") -> str:
    """A filter matching every shadow topic of `thing` (or of every thing)."""
    if thing != "+":
        check_thing(thing)
    return f"$aws/things/{thing}/shadow/#"


def parse_robot_topic(topic: str) -> tuple[str, str] | None:
    """`vahr/robots/{thing}/{kind}` -> (thing, kind), or None for any other topic."""
    found = re.match(_ROBOT_TOPIC, topic)
    return (found["thing"], found["kind"]) if found else None


def parse_shadow_topic(topic: str) -> tuple[str, str | None, str] | None:
    """`$aws/things/{thing}/shadow[/name/{name}]/{op}` -> (thing, name, op), else None."""
    found = re.match(_SHADOW_TOPIC, topic)
    if not found or found["op"] not in SHADOW_OPERATIONS:
        return None
    return found["thing"], found["name"], found["op"]


# The local stack's room channel (docs/voice.md): speech as audio between a robot and the
# local assistant, standing in for the air between a robot's speaker and an Echo.
ROOM_ROBOT_SPEECH = "vahr/room/+/robot"
_ROOM_TOPIC = r"^vahr/room/(?P<thing>[^/]+)/(?P<speaker>robot|assistant)$"


def room_robot_speech(thing: str) -> str:
    """What one robot says into the room (to the assistant)."""
    return f"vahr/room/{check_thing(thing)}/robot"


def room_assistant_speech(thing: str) -> str:
    """What the assistant says back to one robot."""
    return f"vahr/room/{check_thing(thing)}/assistant"


def parse_room_topic(topic: str) -> tuple[str, str] | None:
    """`vahr/room/{thing}/{robot|assistant}` -> (thing, speaker), else None."""
    found = re.match(_ROOM_TOPIC, topic)
    return (found["thing"], found["speaker"]) if found else None


# The operator station's topics (docs/station.md).
# Development only: a fault injected into a simulated robot of the local stack (`vahr
# fault`), and the robot's answer. The local broker's ACL lets a robot hear only its own;
# the cloud's robot policy allows neither, so no robot on AWS IoT Core ever gets one.
ALL_FAULT_ANSWERS = "vahr/dev/robots/+/fault/answer"
_FAULT_ANSWER_TOPIC = r"^vahr/dev/robots/(?P<thing>[^/]+)/fault/answer$"


def robot_fault(thing: str) -> str:
    """Where a fault for `thing` is sent (development only)."""
    return f"vahr/dev/robots/{check_thing(thing)}/fault"


def robot_fault_answer(thing: str) -> str:
    """Where `thing` answers a fault request."""
    return f"{robot_fault(thing)}/answer"


def parse_fault_answer_topic(topic: str) -> str | None:
    """The thing that answered on `topic`, or None."""
    found = re.match(_FAULT_ANSWER_TOPIC, topic)
    return found["thing"] if found else None


# Every exchange with the local Alexa simulator (`vahr up`'s), one message per turn; AWS's
# Alexa publishes nothing here.
ASSISTANT_TURNS = "vahr/assistant/turns"
# What the assistant told the person without being asked: a robot stuck, failed, offline
# (vahr.announce; the local announcer and the cloud's announcer function publish it).
ASSISTANT_ANNOUNCEMENTS = "vahr/assistant/announcements"
# The running experiment session as the station shows it (retained; `vahr experiment`).
EXPERIMENT_STATUS = "vahr/experiment/status"
# What the participant did on the station (interactions, puzzle pieces), for the session's log.
EXPERIMENT_INPUT = "vahr/experiment/input"
