// The station page: one stream of the station's messages (server-sent events, pushed as
// things happen; the page never polls), one store, and the views that draw it.

import { post, replyVoice, setReplyVoice, speak } from "./api.js";
import { Conversation } from "./conversation.js";
import { ExperimentView, Interactions } from "./experiment.js";
import { MapView, setZoneNames } from "./map.js";
import { Panel } from "./panel.js";
import { RobotsPanel } from "./robots.js";
import { Talk } from "./talk.js";

const $ = (id) => document.getElementById(id);

// Benchmarks and tests read what was drawn when (`?metrics=1`).
const metrics = new URLSearchParams(location.search).has("metrics") ? { painted: [], ptt: [], shown: [], messages: 0 } : null;
if (metrics) window.vahrMetrics = metrics;

const COMMANDS_KEPT = 1000; // as many as the station's feed follows (feed.py)
const store = { fleet: null, robots: {}, commands: {}, experiment: null, selected: null, skew: 0 };
const names = {};
const interactions = new Interactions();

const map = new MapView($("map"), { onRobot: select, onZone: (zone) => panel.navigate(store.selected, zone) });
const robots = new RobotsPanel($("robots"), { onSelect: select });
const conversation = new Conversation($("conversation"), $("conversation-filters"), { commands: store.commands, names });
const panel = new Panel({
  robots: $("robot-buttons"), zones: $("zone-buttons"), stopAll: $("stop-all"), weather: $("ask-weather"),
  status: $("panel-status"), note: $("panel-note"), interactions, onSelect: select, names, commands: store.commands,
});
const experiment = new ExperimentView({
  card: $("experiment"), chip: $("session-chip"), briefing: $("briefing"), verdicts: $("verdicts"),
  clock: $("experiment-clock"), puzzle: $("puzzle-count"), less: $("puzzle-less"), more: $("puzzle-more"), names,
  now: () => Date.now() + store.skew,
});
new Talk({ button: $("talk"), level: $("talk-level"), state: $("talk-state"), interactions, metrics });

const voice = $("reply-voice");
voice.value = replyVoice();
voice.addEventListener("change", () => setReplyVoice(voice.value));

function select(thing) {
  store.selected = store.selected === thing ? null : thing;
  map.select(store.selected);
  robots.select(store.selected);
  panel.select(store.selected);
  $("map-hint").textContent = store.selected
    ? `${names[store.selected]} selected: click a zone (or press its key) to send it there.`
    : "Click a robot, then a zone to send it there.";
}

// -- drawing changes, at most once a frame ---------------------------------------------

const dirty = new Set();
let frame = null;
const painted = [];

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
    if (metrics) record(thing, status, robot.reported || {});
  }
  dirty.clear();
  map.updateArms();
  if (metrics && painted.length) {
    // After this frame is painted: the first task once its rendering has run. A posted
    // message, not a timer: timers wait behind other queued work (a stream's next batch).
    afterFrame.push(painted.splice(0));
    frameDone.port2.postMessage(null);
  }
}

const afterFrame = [];
const frameDone = new MessageChannel();
frameDone.port1.onmessage = () => {
  const at = performance.timeOrigin + performance.now();
  for (const marker of afterFrame.shift()) metrics.painted.push({ ...marker, at });
};

// Each robot's status, cargo and zone as drawn, whenever one of them changes (`?metrics=1`).
const lastShown = {};
function record(thing, status, reported) {
  const shown = { thing, status, cargo: Boolean(reported.cargo), zone: reported.zone ?? null };
  const key = JSON.stringify(shown);
  if (lastShown[thing] === key) return;
  lastShown[thing] = key;
  metrics.shown.push(shown);
}

// -- the stream --------------------------------------------------------------------------

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
  }
  conversation.build(snapshot.fleet, snapshot.conversation);
  for (const [thing, robot] of Object.entries(store.robots)) {
    const reported = robot.reported || {};
    const pose = robot.progress?.pose || reported.pose;
    const driving = reported.status === "navigating" && reported.destination;
    map.report(thing, pose, reported.destination, Boolean(driving));
    changed(thing);
  }
  onExperiment(snapshot.experiment);
  if (store.selected) select(store.selected);
}

function onShadow(message) {
  const robot = store.robots[message.thing];
  if (!robot) return;
  robot.reported = message.reported;
  robot.version = message.version;
  robot.last_seen = message.last_seen;
  if (message.reported.status !== "navigating") robot.progress = null;
  const { status, destination, pose, zone } = message.reported;
  const driving = status === "navigating" && destination && zone !== destination;
  map.report(message.thing, pose, destination, Boolean(driving));
  changed(message.thing, metrics ? { thing: message.thing, version: message.version, received: performance.timeOrigin + performance.now() } : null);
}

function onEvent(message) {
  const robot = store.robots[message.thing];
  if (!robot) return;
  robot.last_event = message;
  robot.last_seen = message.last_seen;
  if (message.event === "progress") {
    robot.progress = message;
    map.report(message.thing, message.pose, message.zone, true);
  } else if (["arrived", "stopped", "stuck", "failed", "cancelled", "delivered"].includes(message.event)) {
    robot.progress = null;
    if (message.pose) map.report(message.thing, message.pose, null, false);
  }
  if (["said", "heard", "interpreted"].includes(message.event)) conversation.add({ ...message, robots: [message.thing] });
  changed(message.thing);
}

function onExperiment(status) {
  store.experiment = status && !status.ended ? status : null;
  interactions.setSession(store.experiment ? store.experiment.session : null);
  experiment.update(status);
  map.setLed(store.experiment?.led_on);
  const voiceSession = store.experiment && store.experiment.method !== "keyboard";
  panel.allowOrders(!voiceSession, voiceSession ? "Voice session: orders are given by voice. The panel selects and stops robots." : null);
}

const handlers = {
  snapshot: reset,
  shadow: onShadow,
  event: onEvent,
  presence(message) {
    const robot = store.robots[message.thing];
    if (!robot) return;
    robot.online = message.online;
    robot.last_seen = message.last_seen;
    changed(message.thing);
  },
  command(message) {
    store.commands[message.id] = message;
    // Keep as many commands as the station does: a long session must not grow the page.
    const ids = Object.keys(store.commands);
    for (const old of ids.slice(0, Math.max(0, ids.length - COMMANDS_KEPT))) delete store.commands[old];
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
};

function connect() {
  const state = $("link-state");
  const label = state.querySelector(".label");
  const stream = new EventSource("/api/stream");
  stream.onopen = () => { state.dataset.state = "live"; label.textContent = "Live"; };
  stream.onerror = () => {
    state.dataset.state = stream.readyState === EventSource.CLOSED ? "lost" : "connecting";
    label.textContent = stream.readyState === EventSource.CLOSED ? "Disconnected: reload the page" : "Reconnecting…";
  };
  stream.onmessage = (event) => {
    for (const message of JSON.parse(event.data)) {
      if (metrics) metrics.messages += 1;
      handlers[message.type]?.(message);
    }
  };
}

// -- typing to the assistant ------------------------------------------------------------

$("say-form").addEventListener("submit", async (event) => {
  event.preventDefault();
  const input = $("say-input");
  const utterance = input.value.trim();
  if (!utterance) return;
  input.value = "";
  const sent = post("/api/say", { utterance, origin: "station" });
  interactions.attach(sent.then(
    (turn) => ({ speech: turn.speech, intent: turn.intent, commands: turn.commands || [], asks: turn.intent === "WeatherIntent" }),
    (err) => ({ error: err.message }),
  ));
  try {
    const turn = await sent;
    await speak(turn.speech);
  } catch (err) {
    panel.tell(err.message, true);
  }
});

connect();
window.vahrStation = { store, map };
