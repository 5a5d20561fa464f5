// @ts-check
// The station page: one stream of the station's messages (server-sent events, pushed as
// things happen; the page never polls), one store, and the views that draw it.

import { AlertsView } from "./alerts-view.js";
import { get, post, reason, replyVoice, setReplyVoice, speak } from "./api.js";
import { COMMANDS_LIMIT, DRIVE_ENDS, EXCHANGE_EVENTS } from "./contract.js";
import { Conversation } from "./conversation.js";
import { byId } from "./dom.js";
import { ExperimentView, watchInteractions } from "./experiment.js";
import { t } from "./i18n.js";
import { Interactions } from "./interactions.js";
import { MapView, setZoneNames, zoneText } from "./map.js";
import { applyChange } from "./changes.js";
import { Panel } from "./panel.js";
import { RobotsPanel } from "./robots.js";
import { Talk } from "./talk.js";
import { TasksView } from "./tasks-view.js";
import { ZonesView } from "./zones-view.js";
import { TrailView } from "./trail-view.js";

/** @import { AnnouncementMessage, CommandMessage, EventMessage, ExperimentStatus, FleetView, PageMessage, Reported, RobotChange, RobotView, RobotsMessage, SnapshotMessage } from "./contract.js" */
/** @import { Operator, SayReply } from "./api.js" */

/**
 * What the page knows, kept from the station's messages.
 * @typedef {object} Store
 * @property {FleetView | null} fleet
 * @property {Record<string, RobotView>} robots
 * @property {Record<string, CommandMessage>} commands the commands seen, by id (the views share it)
 * @property {ExperimentStatus | null} experiment the session running, if any
 * @property {string | null} selected the robot selected
 * @property {number} skew the station's clock less the page's, in ms
 */

/** A shadow update on its way to the screen; `station` is when the station received it (its clock). @typedef {{thing: string, version: number, received: number, station?: number | null}} PaintMarker */
/** An alert on its way to the screen. @typedef {{id: string, thing: string | null, kind: string, received: number}} AlertMarker */

/**
 * What was drawn when, for benchmarks and tests (`?metrics=1`, `window.vahrMetrics`).
 * @typedef {object} Metrics
 * @property {Array<PaintMarker & {at: number}>} painted
 * @property {Array<{reply_shown_ms: number, recognizer_ms: number, transcript: string}>} ptt
 * @property {Array<{thing: string, status: string, cargo: boolean, zone: string | null}>} shown
 * @property {Array<AlertMarker & {at: number}>} alerts each alert when painted
 * @property {number} beeps
 * @property {number} messages
 */

// Benchmarks and tests read what was drawn when (`?metrics=1`).
/** @type {Metrics | null} */
const metrics = new URLSearchParams(location.search).has("metrics") ? { painted: [], ptt: [], shown: [], alerts: [], beeps: 0, messages: 0 } : null;
if (metrics) window.vahrMetrics = metrics;

/** @type {Store} */
const store = { fleet: null, robots: {}, commands: {}, experiment: null, selected: null, skew: 0 };
/** The robots' spoken names. @type {Record<string, string>} */
const names = {};
const interactions = new Interactions({ send: (body) => { post("/api/interaction", body).catch(() => {}); } });
watchInteractions(interactions);

const map = new MapView(byId("map", SVGSVGElement), { onRobot: select, onZone: (zone) => panel.navigate(store.selected, zone) });
const robots = new RobotsPanel(byId("robots", HTMLElement), {
  onSelect: select,
  search: { input: byId("robot-search", HTMLInputElement), status: byId("robot-status-filter", HTMLSelectElement), zone: byId("robot-zone-filter", HTMLSelectElement), none: byId("robots-none", HTMLElement), count: byId("robots-count", HTMLElement) },
});
const conversation = new Conversation(byId("conversation", HTMLElement), byId("conversation-filters", HTMLElement), { commands: store.commands, names });
const panel = new Panel({
  robots: byId("robot-buttons", HTMLElement), zones: byId("zone-buttons", HTMLElement), stopAll: byId("stop-all", HTMLButtonElement),
  weather: byId("ask-weather", HTMLButtonElement), status: byId("panel-status", HTMLElement), note: byId("panel-note", HTMLElement),
  interactions, onSelect: select, names, commands: store.commands,
});
const experiment = new ExperimentView({
  card: byId("experiment", HTMLElement), chip: byId("session-chip", HTMLElement), briefing: byId("briefing", HTMLElement),
  verdicts: byId("verdicts", HTMLElement), clock: byId("experiment-clock", HTMLElement), puzzle: byId("puzzle-count", HTMLOutputElement),
  less: byId("puzzle-less", HTMLElement), more: byId("puzzle-more", HTMLElement), names,
  now: () => Date.now() + store.skew,
});
const alerts = new AlertsView({
  box: byId("alerts", HTMLElement), interactions, names,
  onChange(troubled) {
    map.setTroubled(troubled);
    robots.setTroubled(troubled);
  },
  onError: (problem) => panel.tell(problem, true),
  onBeep: () => { if (metrics) metrics.beeps += 1; },
});
const tasks = new TasksView(
  { card: byId("tasks", HTMLElement), list: byId("task-list", HTMLElement), count: byId("task-count", HTMLElement) },
  { nameOf: (thing) => names[thing] || thing, zoneOf: (zone) => (zone.length <= 2 ? `zone ${zone}` : zoneText(zone)) },
);
const zones = new ZonesView(
  { card: byId("zones", HTMLElement), list: byId("zone-switches", HTMLElement), count: byId("zones-count", HTMLElement) },
  { onSwitch: (zone, closed) => post("/api/zone", { zone, closed }).catch((err) => panel.tell(reason(err), true)) },
);
const trail = new TrailView(
  { card: byId("trail", HTMLElement), list: byId("trail-list", HTMLElement), count: byId("trail-count", HTMLElement) },
  (thing) => names[thing] || thing,
);
new Talk({ button: byId("talk", HTMLButtonElement), level: byId("talk-level", HTMLElement), state: byId("talk-state", HTMLElement), interactions, metrics });

// Who works this page, and what their role lets them do: a viewer's page has no controls
// that send robots (the station refuses them anyway); stopping stays, as it is anyone's.
const ROLE_WORDS = {
  /** @param {string} name */
  viewer: (name) => t("{name} is a viewer: you may watch the robots, ask the assistant and stop them; sending robots needs an operator.", { name }),
};
/** @param {Operator} operator */
function showOperator(operator) {
  const commands = operator.may.includes("command");
  panel.allowCommands(commands);
  byId("zone-row", HTMLElement).hidden = !commands;
  if (!commands) byId("map-hint", HTMLElement).textContent = t("Click a robot to follow it.");
  // Closing and opening zones changes the whole fleet's service: a supervisor's.
  zones.allow(operator.may.includes("fleet"));
  const note = byId("panel-role", HTMLElement);
  note.hidden = commands;
  if (!commands) note.textContent = ROLE_WORDS.viewer(operator.name || operator.id);
  if (!operator.signed_in) return;
  byId("operator", HTMLElement).hidden = false;
  byId("operator-name", HTMLElement).textContent = `${operator.name || operator.id} · ${t(operator.role)}`;
}
byId("sign-out", HTMLButtonElement).addEventListener("click", async () => {
  await post("/api/signout", {}).catch(() => {});
  location.replace("/");
});
/** @type {Promise<Operator>} */
const me = get("/api/me");
me.then(showOperator, (err) => panel.tell(reason(err), true));

const voice = byId("reply-voice", HTMLSelectElement);
voice.value = replyVoice();
voice.addEventListener("change", () => setReplyVoice(voice.value));

/** Select `thing` (again: deselect it). @param {string} thing */
function select(thing) {
  store.selected = store.selected === thing ? null : thing;
  map.select(store.selected);
  robots.select(store.selected);
  panel.select(store.selected);
  byId("map-hint", HTMLElement).textContent = !panel.commandsAllowed
    ? t("Click a robot to follow it.")
    : store.selected
      ? t("{robot} selected: click a zone (or press its key) to send it there.", { robot: names[store.selected] })
      : t("Click a robot, then a zone to send it there.");
}

// -- drawing changes, at most once a frame ---------------------------------------------

/** @type {Set<string>} */
const dirty = new Set();
/** @type {number | null} */
let frame = null;
/** @type {PaintMarker[]} */
const painted = [];

/** @param {string} thing @param {PaintMarker | null} [marker] */
function changed(thing, marker = null) {
  dirty.add(thing);
  if (marker) painted.push(marker);
  if (frame === null) frame = requestAnimationFrame(draw);
}

function draw() {
  frame = null;
  for (const thing of dirty) {
    const robot = store.robots[thing];
    if (!robot) continue;
    map.update(thing, robot);
    robots.update(thing, robot, store.commands);
    const status = robot.online === false ? "offline" : robot.reported?.status || "idle";
    panel.colour(thing, status);
    if (metrics) record(metrics, thing, status, robot.reported || {});
  }
  dirty.clear();
  map.updateArms();
  if (metrics && painted.length) {
    const markers = painted.splice(0);
    afterPaint((at) => { for (const marker of markers) metrics.painted.push({ ...marker, at }); });
  }
}

// Call from an animation frame: `then` runs once that frame is painted, with the time. The
// first task after its rendering: a posted message, not a timer, which would wait behind
// other queued work (a stream's next batch).
/** @type {Array<(at: number) => void>} */
const afterFrame = [];
const frameDone = new MessageChannel();
frameDone.port1.onmessage = () => afterFrame.shift()?.(performance.timeOrigin + performance.now());
/** @param {(at: number) => void} then */
function afterPaint(then) {
  afterFrame.push(then);
  frameDone.port2.postMessage(null);
}

// Each robot's status, cargo and zone as drawn, whenever one of them changes (`?metrics=1`).
/** @type {Record<string, string>} */
const lastShown = {};
/** @param {Metrics} metrics @param {string} thing @param {string} status @param {Reported} reported */
function record(metrics, thing, status, reported) {
  const cargo = Boolean(reported.cargo), zone = reported.zone ?? null;
  const key = `${status}|${cargo}|${zone}`;
  if (lastShown[thing] === key) return;
  lastShown[thing] = key;
  metrics.shown.push({ thing, status, cargo, zone });
}

// -- the stream --------------------------------------------------------------------------

/** @param {SnapshotMessage} snapshot */
function reset(snapshot) {
  const first = store.fleet === null;
  store.fleet = snapshot.fleet;
  store.robots = snapshot.robots;
  for (const key of Object.keys(store.commands)) delete store.commands[key];
  Object.assign(store.commands, snapshot.commands);
  store.skew = snapshot.server_time - Date.now();
  for (const robot of snapshot.fleet.robots) names[robot.thing] = robot.name;
  setZoneNames(snapshot.fleet.zones);
  if (first) {
    map.build(snapshot.fleet);
    robots.build(snapshot.fleet);
    panel.build(snapshot.fleet);
    zones.build(snapshot.fleet);
  }
  conversation.build(snapshot.fleet, snapshot.conversation);
  for (const [thing, robot] of Object.entries(store.robots)) {
    /** @type {Reported} */
    const reported = robot.reported || {};
    const pose = robot.progress?.pose || reported.pose;
    const driving = reported.status === "navigating" && (reported.destination || reported.path);
    map.report(thing, pose, reported.destination, Boolean(driving), reported.path);
    changed(thing);
  }
  onExperiment(snapshot.experiment);
  tasks.update(snapshot.tasks);
  map.setClosed(snapshot.tasks?.closed || []);
  robots.setOutOfService(snapshot.tasks?.out_of_service || []);
  zones.update(snapshot.tasks);
  trail.update(snapshot.trail);
  alerts.reset(snapshot.alerts, first);
  if (store.selected) select(store.selected);
}

/** @param {AnnouncementMessage} message */
function onAnnouncement(message) {
  conversation.add(message);
  if (!alerts.add(message) || !metrics) return;
  const marker = { id: message.id, thing: message.thing, kind: message.kind, received: performance.timeOrigin + performance.now() };
  requestAnimationFrame(() => afterPaint((at) => metrics.alerts.push({ ...marker, at })));
}

/** @param {RobotsMessage} message */
function onRobots(message) {
  const received = metrics ? performance.timeOrigin + performance.now() : 0;
  for (const change of message.changes) onChange(change, received);
}

/** One robot's change (only what changed is in it). @param {RobotChange} change @param {number} received */
function onChange(change, received) {
  const robot = store.robots[change.thing];
  if (!robot) return;
  applyChange(robot, change);
  const ended = change.last_event && DRIVE_ENDS.includes(change.last_event.event) ? change.last_event : null;
  const path = robot.reported?.path;
  if (ended?.pose) map.report(change.thing, ended.pose, null, false);
  if (change.progress) map.report(change.thing, change.progress.pose, change.progress.zone, true, path);
  if (change.reported || change.removed) {
    const { status, destination, pose, zone } = robot.reported || {};
    // A robot leaving a closed zone drives with a path and no destination.
    const driving = status === "navigating" && ((destination && zone !== destination) || path);
    if (!change.progress) map.report(change.thing, pose, destination, Boolean(driving), path);
  }
  const marker = metrics && change.version !== undefined ? { thing: change.thing, version: change.version, received, station: change.last_seen } : null;
  changed(change.thing, marker);
}

// What a robot said, heard or understood (the rest of what robots do comes as changes).
/** @param {EventMessage} message */
function onEvent(message) {
  const robot = store.robots[message.thing];
  if (!robot) return;
  robot.last_event = message;
  robot.last_seen = message.last_seen;
  if (EXCHANGE_EVENTS.includes(message.event)) conversation.add({ ...message, robots: [message.thing] });
  changed(message.thing);
}

/** @param {ExperimentStatus | null} status */
function onExperiment(status) {
  store.experiment = status && !status.ended ? status : null;
  interactions.setSession(store.experiment ? store.experiment.session : null);
  experiment.update(status);
  map.setLed(store.experiment?.led_on);
  const voiceSession = store.experiment && store.experiment.method !== "keyboard";
  panel.allowOrders(!voiceSession, voiceSession ? t("Voice session: orders are given by voice. The panel selects and stops robots.") : null);
}

/** What the page does with each message, by its type. @type {{[T in PageMessage["type"]]: (message: Extract<PageMessage, {type: T}>) => void}} */
const handlers = {
  snapshot: reset,
  robots: onRobots,
  event: onEvent,
  command(message) {
    store.commands[message.id] = message;
    // Keep as many commands as the station does: a long session must not grow the page.
    const ids = Object.keys(store.commands);
    for (const old of ids.slice(0, Math.max(0, ids.length - COMMANDS_LIMIT))) delete store.commands[old];
    if (message.source !== "alexa") conversation.add(message);
  },
  ack(message) {
    const command = store.commands[message.id];
    if (!command) return;
    command.acks[message.thing] = { event: message.event, latency_ms: message.latency_ms };
    conversation.acknowledged(message.id);
    panel.acknowledged(message.id, message.thing, command.acks[message.thing]);
  },
  turn(message) {
    conversation.add(message);
    experiment.heard(message.speech);
  },
  experiment(message) {
    onExperiment(message.status);
  },
  announcement: onAnnouncement,
  alert_acknowledged(message) {
    alerts.acknowledged(message.ids);
  },
  tasks(message) {
    tasks.update(message);
    map.setClosed(message.closed || []);
    robots.setOutOfService(message.out_of_service || []);
    zones.update(message);
  },
  trail(message) {
    trail.update(message);
  },
};

function connect() {
  const state = byId("link-state", HTMLElement);
  const label = /** @type {HTMLElement} */ (state.querySelector(".label"));
  const stream = new EventSource("/api/stream");
  stream.onopen = () => { state.dataset.state = "live"; label.textContent = t("Live"); };
  stream.onerror = () => {
    state.dataset.state = stream.readyState === EventSource.CLOSED ? "lost" : "connecting";
    label.textContent = stream.readyState === EventSource.CLOSED ? t("Disconnected: reload the page") : t("Reconnecting…");
  };
  stream.onmessage = (event) => {
    for (const message of /** @type {PageMessage[]} */ (JSON.parse(event.data))) {
      if (metrics) metrics.messages += 1;
      // A message of a type this page does not know (a newer station) is passed over.
      const handle = /** @type {((message: PageMessage) => void) | undefined} */ (handlers[message.type]);
      handle?.(message);
    }
  };
}

// -- typing to the assistant ------------------------------------------------------------

byId("say-form", HTMLFormElement).addEventListener("submit", async (event) => {
  event.preventDefault();
  const input = byId("say-input", HTMLInputElement);
  const utterance = input.value.trim();
  if (!utterance) return;
  input.value = "";
  /** @type {Promise<SayReply>} */
  const sent = post("/api/say", { utterance, origin: "station" });
  interactions.attach(sent.then(
    (turn) => ({ speech: turn.speech, intent: turn.intent, commands: turn.commands || [], asks: turn.intent === "WeatherIntent" }),
    (err) => ({ error: err.message }),
  ));
  try {
    const turn = await sent;
    await speak(turn.speech);
  } catch (err) {
    panel.tell(reason(err), true);
  }
});

connect();
window.vahrStation = { store, map, alerts };
