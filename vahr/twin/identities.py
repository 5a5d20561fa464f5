"""The local stack's own MQTT identities: a certificate, and so a client id, for each client.

The broker makes a certificate's common name both the user its ACL checks and the client id
(`use_identity_as_username`, `use_username_as_clientid`), as AWS IoT binds a robot's client
id to its thing. Two connections with one identity would take each other's session over, so
every part of the stack that holds a connection of its own has a name of its own; the ACL
gives each of these names the services' rights and no robot can take one (their names all
start with `vahr-`, reserved by `vahr.protocol.identities`).
"""

from __future__ import annotations

from vahr.pki import SERVICE_COMMON_NAME

# For a tool or a test on the stack's broker: one client at a time.
TOOL = SERVICE_COMMON_NAME
SHADOWS = "vahr-shadow-service"
WATCHER = "vahr-watcher-local"
ANNOUNCER = "vahr-announcer-local"
DISPATCHER = "vahr-dispatcher-local"
ROOM = "vahr-room-local"
STATION = "vahr-station-local"
SWARM = "vahr-swarm-local"
# A second tool at once (a test that watches while another client of its own publishes).
SECOND_TOOL = "vahr-service-2"

SERVICES = (TOOL, SECOND_TOOL, SHADOWS, WATCHER, ANNOUNCER, DISPATCHER, ROOM, STATION, SWARM)
