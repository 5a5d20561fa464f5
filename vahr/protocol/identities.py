"""Who may connect as whom: the client ids the system's own parts use, kept from robots.

A robot connects as its thing name (AWS IoT's policy binds `iot:Connect` to
`client/${iot:Connection.Thing.ThingName}`; the local broker makes the certificate's common
name the client id). The system's own parts (the local services, the operator station,
the experiment's recorder) connect under names starting with `vahr-`, so a robot's thing
name may not start so: otherwise a robot's certificate could take over a station's or a
service's session, or be mistaken for one in a log. Fleet files and `robot-agent
provision` refuse such a name in one line.
"""

from __future__ import annotations

from vahr.protocol.topics import check_thing

RESERVED_PREFIX = "vahr-"
# On AWS each connects with a certificate of its own whose policy allows only these.
STATION_CLIENT_PREFIX = "vahr-station-"
RECORDER_CLIENT_PREFIX = "vahr-experiment-"


def check_robot_thing(thing: str) -> str:
    """Return `thing` if a robot may take it, else raise ValueError ("thing: ...")."""
    check_thing(thing)
    if thing.lower().startswith(RESERVED_PREFIX):
        raise ValueError(
            f"thing: {thing!r} is reserved: names starting with {RESERVED_PREFIX!r} are the "
            "system's own identities (services, stations, recorders), never a robot's"
        )
    return thing
