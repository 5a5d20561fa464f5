// @ts-check
// The station's page contract: the messages the page is sent and sends, and the constants
// it shares with the station. Generated from vahr/station/page_messages.py by
// `python -m vahr.station.contract`: do not edit; change the structs and run it again.

/**
 * A robot's first answer to a command, with the time it took from the command being seen (the
 * acknowledgment latency the conversation shows).
 * @typedef {object} AckMessage
 * @property {"ack"} type
 * @property {string} id
 * @property {string} thing
 * @property {string} event
 * @property {number} latency_ms
 */

/**
 * A robot's first answer to a command (an event, or its shadow's `last_command` result) and the
 * time from the command being seen to it.
 * @typedef {object} Acknowledgment
 * @property {string} event
 * @property {number} latency_ms
 */

/**
 * Someone acknowledged an alert on a station page: these announcements (the one acknowledged
 * and any other still open about the same robot and trouble) are no longer shown as alerts.
 * @typedef {object} AlertAcknowledgedMessage
 * @property {"alert_acknowledged"} type
 * @property {Array<string>} ids
 */

/**
 * What the assistant told the person unprompted (a robot stuck, failed, offline...), with the
 * robots it concerns. The page shows it as an alert until someone acknowledges it, and in the
 * conversation.
 * @typedef {object} AnnouncementMessage
 * @property {"announcement"} type
 * @property {Array<string>} robots
 * @property {string} id
 * @property {string} time
 * @property {string|null} thing
 * @property {"battery_low"|"cancelled"|"done"|"failed"|"offline"|"stuck"|"waiting"} kind
 * @property {number} priority
 * @property {string} speech
 * @property {string|null} reason
 * @property {string} person
 * @property {string} opened_at
 */

/**
 * An entry in the trail: its number, the hash of the one before, and its own.
 * @typedef {object} AuditRecord
 * @property {string} time
 * @property {string} who
 * @property {string|null} name
 * @property {string|null} role
 * @property {string} channel
 * @property {string|null} words
 * @property {string|null} intent
 * @property {Record<string, string|null>} slots
 * @property {Array<string>} robots
 * @property {Array<string>} commands
 * @property {"answered"|"asked"|"cancelled"|"confirmed"|"failed"|"refused"|"sent"|"unsent"} outcome
 * @property {string|null} reason
 * @property {number} seq
 * @property {string} prev
 * @property {string} hash
 */

/**
 * A robot's battery as its backend reads it: charge in percent and whether it charges.
 * @typedef {object} Battery
 * @property {number} percent
 * @property {boolean} [charging]
 */

/**
 * A command seen on a command topic (from the assistant, the console, a robot), to `target` (a
 * thing, or "fleet" for every robot in `robots`); `acks` grows as robots answer. `seen` is when
 * the station saw it (ms since the epoch).
 * @typedef {object} CommandMessage
 * @property {"command"} type
 * @property {string} id
 * @property {string} target
 * @property {Array<string>} robots
 * @property {string} action
 * @property {CommandParams} params
 * @property {string} source
 * @property {number} seen
 * @property {Record<string, Acknowledgment>} acks
 */

/**
 * A command's params as seen: only those of its action are present.
 * @typedef {object} CommandParams
 * @property {string} [zone]
 * @property {string|null} [after]
 */

/**
 * The belt that brings packages to the loading arm: its centre line and width.
 * @typedef {object} Conveyor
 * @property {Point} start
 * @property {Point} end
 * @property {number} width
 */

/**
 * What a robot did, published on `vahr/robots/{thing}/events`.
 *
 * Only the fields that apply are sent: `zone` for arrived/loaded/delivered, `reason` for
 * rejected/failed/stuck/cancelled, `progress` (0..1 of the path's length) for progress (with
 * `eta_s`, seconds left, where the robot knows it, and `distance_remaining_m` from a backend
 * that estimates it, such as Nav2), `text` for what was said or heard, `intent` and
 * `confidence` for interpreted.
 * @typedef {object} Event
 * @property {"accepted"|"arrived"|"cancelled"|"delivered"|"done"|"failed"|"heard"|"interpreted"|"loaded"|"progress"|"rejected"|"said"|"stopped"|"stuck"|"waiting"} event
 * @property {string} thing
 * @property {string} at
 * @property {string|null} [command_id]
 * @property {string|null} [action]
 * @property {string|null} [zone]
 * @property {string|null} [reason]
 * @property {number|null} [progress]
 * @property {number|null} [eta_s]
 * @property {number|null} [distance_remaining_m]
 * @property {ReportedPose|null} [pose]
 * @property {string|null} [text]
 * @property {string|null} [intent]
 * @property {number|null} [confidence]
 */

/**
 * What a robot said, heard or understood (`EXCHANGE_EVENTS`), with when the station last heard
 * from it; in the conversation, with the robots it concerns.
 * @typedef {object} EventMessage
 * @property {"event"} type
 * @property {number} last_seen
 * @property {Array<string>} [robots]
 * @property {"accepted"|"arrived"|"cancelled"|"delivered"|"done"|"failed"|"heard"|"interpreted"|"loaded"|"progress"|"rejected"|"said"|"stopped"|"stuck"|"waiting"} event
 * @property {string} thing
 * @property {string} at
 * @property {string|null} [command_id]
 * @property {string|null} [action]
 * @property {string|null} [zone]
 * @property {string|null} [reason]
 * @property {number|null} [progress]
 * @property {number|null} [eta_s]
 * @property {number|null} [distance_remaining_m]
 * @property {ReportedPose|null} [pose]
 * @property {string|null} [text]
 * @property {string|null} [intent]
 * @property {number|null} [confidence]
 */

/**
 * The running session, or None when none runs.
 * @typedef {object} ExperimentMessage
 * @property {"experiment"} type
 * @property {ExperimentStatus|null} status
 */

/**
 * The running session for the station (retained on `topics.EXPERIMENT_STATUS`).
 *
 * The weather is left out on purpose: a keyboard-and-mouse participant learns it by asking the
 * assistant, and the station shows only what was answered.
 * @typedef {object} ExperimentStatus
 * @property {string} session
 * @property {string} participant
 * @property {"keyboard"|"vahr"} method
 * @property {number} trial
 * @property {boolean} [simulated]
 * @property {Record<string, string>} [assignments]
 * @property {"I"|"II"|"III"|null} [task]
 * @property {Record<string, ExperimentTaskStatus>} [tasks]
 * @property {Array<string>} [allowed]
 * @property {number} [puzzle]
 * @property {boolean} [led_on]
 * @property {string|null} [started_at]
 * @property {boolean} [ended]
 * @property {string|null} [at]
 */

/**
 * One task as the judge sees it now: not started, running (with the verdict so far), or ended
 * with success or failure and why.
 * @typedef {object} ExperimentTaskStatus
 * @property {"failure"|"running"|"success"|"waiting"} state
 * @property {string} [reason]
 * @property {string} [title]
 * @property {string|null} [started_at]
 * @property {string|null} [ended_at]
 */

/**
 * The fleet as the page draws it: robots, zones and the floor (`Fleet.layout`), and the map
 * when the floor is one.
 * @typedef {object} FleetView
 * @property {Array<RobotEntry>} robots
 * @property {Array<ZoneEntry>} zones
 * @property {Floor} floor
 * @property {string} experiment_thing
 * @property {FloorMap|null} map
 * @property {number} charge_below
 */

/**
 * The floor: the rectangle from `origin` of `width` by `height` metres, its walls, the
 * conveyor, where each zone's arm stands (by zone id) and the task III LED.
 *
 * With `map` (a ROS map_server YAML, relative to the fleet file; `load_fleet` makes it
 * absolute) the map is the floor: `width`, `height` and `origin` are the map's, filled in by
 * `vahr.navigation` when it reads it, and `robot_radius` is how far robots keep from anything
 * that is not free space. Without a map, `width` and `height` are required.
 * @typedef {object} Floor
 * @property {number|null} width
 * @property {number|null} height
 * @property {Point} origin
 * @property {Array<Segment>} walls
 * @property {Conveyor|null} conveyor
 * @property {Record<string, Point>} arms
 * @property {Point|null} led
 * @property {string|null} map
 * @property {number} robot_radius
 */

/**
 * A floor that is a map: its picture (`image`, a PNG the station serves: occupied cells dark,
 * free ones light, unknown ones clear) laid from `origin` at `resolution` metres a pixel,
 * `columns` by `rows`; `known` is the part that is not unknown, which the page zooms to.
 * @typedef {object} FloorMap
 * @property {string} image
 * @property {Point} origin
 * @property {number} resolution
 * @property {number} columns
 * @property {number} rows
 * @property {MapExtent} known
 */

/**
 * What the recognizer made of a spoken clip.
 * @typedef {object} Heard
 * @property {string} transcript
 * @property {number} confidence
 * @property {boolean} accepted
 * @property {number} [seconds]
 */

/**
 * A click, key press or push-to-talk on the station, sent when it starts and when it ends (same
 * `id`). The end says what came of it: the commands it sent, or for a question to the assistant
 * (`asks`) the reply; `counts` is False for input that sends nothing by design (selecting a
 * robot), which is interaction time but not communication.
 * @typedef {object} Interaction
 * @property {"interaction"} kind
 * @property {string} session
 * @property {string} id
 * @property {"ended"|"started"} phase
 * @property {"click"|"key"|"voice"} channel
 * @property {string} at
 * @property {string} sent
 * @property {string} [text]
 * @property {Array<string>} [commands]
 * @property {boolean} [counts]
 * @property {boolean} [asks]
 * @property {string|null} [speech]
 * @property {string|null} [intent]
 * @property {string|null} [error]
 */

/**
 * The last command a robot saw and what became of it. `id` is what the skill waits for.
 *
 * Every field is sent, `null` included: a shadow update merges objects key by key, so a reason
 * left out would keep the reason of an earlier command (null deletes it). `zone` is the zone
 * the command was for; its `reason` names that zone by this id, which speech and the station
 * replace with the zone's spoken name (`vahr.domain.fleet.reason_said`).
 * @typedef {object} LastCommand
 * @property {string} id
 * @property {string} action
 * @property {"accepted"|"cancelled"|"done"|"failed"|"rejected"} result
 * @property {string|null} [reason]
 * @property {string|null} [zone]
 */

/**
 * A rectangle of the map frame, in metres.
 * @typedef {object} MapExtent
 * @property {number} left
 * @property {number} bottom
 * @property {number} right
 * @property {number} top
 */

/**
 * A point on the floor in the `map` frame, in metres.
 * @typedef {object} Point
 * @property {number} x
 * @property {number} y
 */

/**
 * A planar pose in the `map` frame: metres and radians.
 * @typedef {object} Pose
 * @property {number} x
 * @property {number} y
 * @property {number} theta
 */

/**
 * Puzzle pieces the observer counted (a negative count corrects a miscount).
 * @typedef {object} PuzzleInput
 * @property {"puzzle"} kind
 * @property {string} session
 * @property {number} count
 * @property {string} at
 * @property {string} sent
 */

/**
 * A robot's reported state. The first five fields are the contract; the rest help speech.
 * @typedef {object} Reported
 * @property {"error"|"idle"|"loading"|"navigating"|"stopped"|"stuck"|"unloading"|"waiting"} [status]
 * @property {string|null} [zone]
 * @property {boolean} [cargo]
 * @property {LastCommand|null} [last_command]
 * @property {boolean} [connected]
 * @property {string|null} [destination]
 * @property {string|null} [task]
 * @property {ReportedPose|null} [pose]
 * @property {Battery|null} [battery]
 * @property {Array<[number, number]>|null} [path]
 */

/**
 * Where a robot says it is, in the `map` frame (metres, radians): in its events, its shadow's
 * `reported.pose` and the fleet index. Read tolerantly, as everything a robot reports is; the
 * fleet file's poses are `vahr.domain.Pose`, read strictly.
 * @typedef {object} ReportedPose
 * @property {number} x
 * @property {number} y
 * @property {number} theta
 */

/**
 * What changed of one robot since the page last heard of it: a field is present only when it
 * changed. `reported` holds the reported state's top-level fields that changed, with their new
 * values, and `removed` those that are gone: the page merges them into the state it has.
 * `version` is the shadow version that brings it to; `last_event` the robot's latest event
 * other than progress (an exchange with the assistant is sent as an `EventMessage` instead);
 * `progress` the drive's latest progress event (None once the drive ended). A page applies
 * `last_event` before `progress`: `progress` is always the state after both.
 * @typedef {object} RobotChange
 * @property {string} thing
 * @property {Reported} [reported]
 * @property {Array<string>} [removed]
 * @property {number} [version]
 * @property {boolean} [online]
 * @property {number|null} [last_seen]
 * @property {Event|null} [progress]
 * @property {Event} [last_event]
 */

/**
 * A robot as the page draws it: its spoken name, its key (1-9, None past nine robots) and where
 * it starts.
 * @typedef {object} RobotEntry
 * @property {string} thing
 * @property {string} name
 * @property {string|null} key
 * @property {Pose} start
 */

/**
 * What a page knows of one robot: its reported shadow and version, presence, when it was last
 * seen (ms since the epoch), its last event and the progress of the drive under way. None until
 * known.
 * @typedef {object} RobotView
 * @property {Reported|null} reported
 * @property {number|null} version
 * @property {boolean|null} online
 * @property {number|null} last_seen
 * @property {Event|null} last_event
 * @property {Event|null} progress
 */

/**
 * The robots that changed since the page's last message, each once, with only what changed
 * (shadow updates, presence and drive progress coalesced per robot): at most one of these
 * reaches a page per frame however many robots report.
 * @typedef {object} RobotsMessage
 * @property {"robots"} type
 * @property {Array<RobotChange>} changes
 */

/**
 * A straight piece of wall from `start` to `end`.
 * @typedef {object} Segment
 * @property {Point} start
 * @property {Point} end
 */

/**
 * What a page starts from: the fleet, every robot, the conversation so far, the commands seen
 * with their acknowledgments, the session, the announcements nobody has acknowledged yet
 * (oldest first), the station's clock (ms since the epoch) for the page to correct its own, the
 * fleet's task queue when the station has read it, and the audit trail's latest records when
 * the station reads one.
 * @typedef {object} SnapshotMessage
 * @property {"snapshot"} type
 * @property {FleetView} fleet
 * @property {Record<string, RobotView>} robots
 * @property {Array<TurnMessage|CommandMessage|EventMessage|AnnouncementMessage>} conversation
 * @property {Record<string, CommandMessage>} commands
 * @property {ExperimentStatus|null} experiment
 * @property {Array<AnnouncementMessage>} alerts
 * @property {number} server_time
 * @property {TasksMessage|null} tasks
 * @property {TrailMessage|null} trail
 */

/**
 * One robot's share of an order, as the store keeps it and `GET /vahr/tasks` shows it.
 *
 * `id` is also the id of the command published for it (so republishing after a restart is
 * executed once, docs/protocol.md). `robots` lists the only robots that may take it (a group's
 * member, a robot in a named zone); empty means any. `created_at` (RFC 3339 UTC with
 * microseconds) then `id` order the queue. `version` grows by one on every write; stores use it
 * for their conditional writes.
 * @typedef {object} Task
 * @property {string} id
 * @property {string} request
 * @property {"charge"|"deliver"|"navigate"} kind
 * @property {string} zone
 * @property {string|null} pickup
 * @property {string|null} group
 * @property {Array<string>} robots
 * @property {"assigned"|"cancelled"|"done"|"queued"} status
 * @property {string|null} thing
 * @property {string} created_at
 * @property {string|null} assigned_at
 * @property {"cancelled"|"done"|"failed"|"preempted"|"rejected"|null} outcome
 * @property {number} version
 */

/**
 * The fleet's task queue, sent when it changed: every task the dispatcher lists (`GET
 * {api}/vahr/tasks`, `vahr.dispatch.Task`: what is to be done where, its state, the robot that
 * took it), in its order, the zones closed now and the robots out of service; `available` is
 * False when the deployment has no dispatcher to ask.
 * @typedef {object} TasksMessage
 * @property {"tasks"} type
 * @property {Array<Task>} tasks
 * @property {boolean} available
 * @property {Array<string>} closed
 * @property {Array<string>} out_of_service
 */

/**
 * The latest records of the audit trail (`vahr.protocol.audit`, oldest first), sent when new
 * ones came: who did what, through which channel, and what came of it.
 * @typedef {object} TrailMessage
 * @property {"trail"} type
 * @property {Array<AuditRecord>} records
 */

/**
 * One exchange with the assistant, with the robots it concerns.
 * @typedef {object} TurnMessage
 * @property {"turn"} type
 * @property {Array<string>} robots
 * @property {string} utterance
 * @property {string} speech
 * @property {string|null} [intent]
 * @property {Record<string, Record<string, string|null>>} [slots]
 * @property {Array<string>} [commands]
 * @property {number} [latency_ms]
 * @property {boolean} [session_open]
 * @property {string} [request_type]
 * @property {string|null} [reprompt]
 * @property {string} [origin]
 * @property {Heard|null} [heard]
 * @property {string|null} [at]
 */

/**
 * A zone as the page draws it, with its key (its first letter, None if another zone took it).
 * @typedef {object} ZoneEntry
 * @property {string} id
 * @property {string} name
 * @property {Pose} pose
 * @property {number} radius
 * @property {"loader"|"unloader"|null} arm
 * @property {string|null} key
 * @property {Array<Point>|null} area
 */

/** @typedef {SnapshotMessage|RobotsMessage|EventMessage|CommandMessage|AckMessage|TurnMessage|ExperimentMessage|AnnouncementMessage|AlertAcknowledgedMessage|TasksMessage|TrailMessage} PageMessage */

/** @typedef {TurnMessage|CommandMessage|EventMessage|AnnouncementMessage} ConversationEntry */

/** @typedef {Interaction|PuzzleInput} StationInput */

/** What a robot can report it did. @typedef {"accepted"|"rejected"|"progress"|"arrived"|"loaded"|"delivered"|"stuck"|"failed"|"stopped"|"done"|"cancelled"|"waiting"|"said"|"heard"|"interpreted"} EventKind */

/** Events after which a robot is no longer driving: the page stops moving it. @type {ReadonlyArray<EventKind>} */
export const DRIVE_ENDS = Object.freeze(["arrived", "cancelled", "delivered", "failed", "stopped", "stuck"]);

/** The robots' own exchanges with the assistant, which the conversation shows. @type {ReadonlyArray<EventKind>} */
export const EXCHANGE_EVENTS = Object.freeze(["heard", "interpreted", "said"]);

/** Commands whose acknowledgments the station follows; older ones are forgotten. @type {number} */
export const COMMANDS_LIMIT = 1000;

/** Conversation entries the station keeps for a new page. @type {number} */
export const CONVERSATION_LIMIT = 400;
