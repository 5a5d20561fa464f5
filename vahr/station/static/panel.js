// @ts-check
// The keyboard-and-mouse panel: the paper's baseline method. Select a robot (a click on the
// map or here, or its number key), then a zone (a click, or its letter key, which the fleet
// decides: `keysHint` says them above the panel) to send it there; the
// arms load and unload on arrival. Esc stops every robot. "Ask the weather" asks the
// assistant, as the paper's keyboard participants did. "Any robot" (key 0), then a zone,
// asks the assistant to send a robot there, as a person would say it: the fleet's dispatcher
// picks the robot, or queues the task when none is free.

import { post, reason } from "./api.js";
import { said, t, tNodes } from "./i18n.js";
import { statusColour, zoneText } from "./map.js";
import { typing } from "./talk.js";

/** @import { Acknowledgment, CommandMessage, FleetView, ZoneEntry } from "./contract.js" */
/** @import { CommandReply, SayReply } from "./api.js" */
/** @import { Interactions } from "./interactions.js" */

/**
 * The panel's elements, the page's interactions, and what it shares with the page's store.
 * @typedef {object} PanelParts
 * @property {HTMLElement} robots the robots' buttons go here
 * @property {HTMLElement} zones the zones' buttons go here
 * @property {HTMLButtonElement} stopAll
 * @property {HTMLButtonElement} weather
 * @property {HTMLElement} status
 * @property {HTMLElement} note
 * @property {Interactions} interactions
 * @property {(thing: string) => void} onSelect
 * @property {Record<string, string>} names the robots' spoken names
 * @property {Record<string, CommandMessage>} commands the commands seen, by id
 */

// The words the panel sends and shows for "any robot" (one place, for translation).
const ANY = {
  label: t("Any robot"),
  key: "0",
  /** @param {string} zone the zone as spoken ("zone c", "loading zone"), in the assistant's language */
  utterance: (zone) => said("send a robot to {zone}", { zone }),
  /** @param {string} zone */
  title: (zone) => t("Send any free robot to {zone}", { zone }),
  select: t("Any robot selected: click a zone (or press its key) to send the free robot nearest it."),
};

/**
 * The keys this fleet's panel answers to, said once above it: its robots' numbers, its
 * zones' letters (runs of consecutive letters as "A–D"), stop and talk.
 * @param {FleetView} fleet
 * @returns {Node[]}
 */
export function keysHint(fleet) {
  const numbers = fleet.robots.map((robot) => robot.key).filter((k) => k !== null && k !== undefined);
  const letters = fleet.zones.map((zone) => zone.key).filter((k) => k !== null && k !== undefined);
  /** @type {Node[]} */
  const out = [document.createTextNode(`${t("Keys:")} `)];
  /** @param {string[]} keys */
  const keyRun = (keys) => {
    /** @type {Node[]} */
    const nodes = [];
    keys.forEach((k, i) => {
      if (i > 0) nodes.push(document.createTextNode(k === "–" || keys[i - 1] === "–" ? "" : ", "));
      nodes.push(k === "–" ? document.createTextNode("–") : key(k));
    });
    return nodes;
  };
  if (numbers.length) out.push(...keyRun(numbers.length > 2 ? [numbers[0], "–", numbers[numbers.length - 1]] : numbers), document.createTextNode(` ${t("robot")} · `));
  out.push(key(ANY.key), document.createTextNode(` ${t("any robot")} · `));
  if (letters.length) out.push(...keyRun(runs(letters)), document.createTextNode(` ${t("zone")} · `));
  out.push(key("Esc"), document.createTextNode(` ${t("stop all")} · `));
  out.push(...tNodes("hold {space} to talk", { space: key(t("Space")) }));
  return out;
}

/** Letters with runs of three or more consecutive ones as first, "–", last. @param {string[]} letters */
function runs(letters) {
  /** @type {string[]} */
  const out = [];
  for (let i = 0; i < letters.length; ) {
    let j = i;
    while (j + 1 < letters.length && letters[j + 1].charCodeAt(0) === letters[j].charCodeAt(0) + 1) j += 1;
    if (j - i >= 2) out.push(letters[i], "–", letters[j]);
    else out.push(...letters.slice(i, j + 1));
    i = j + 1;
  }
  return out;
}

/** @param {string | undefined} label @param {string} [className] */
function button(label, className = "btn") {
  const made = document.createElement("button");
  made.type = "button";
  made.className = className;
  if (label !== undefined) made.textContent = label;
  return made;
}

/** @param {string} letter */
function key(letter) {
  const kbd = document.createElement("kbd");
  kbd.textContent = letter;
  return kbd;
}

export class Panel {
  /** @param {PanelParts} parts */
  constructor({ robots, zones, stopAll, weather, status, note, interactions, onSelect, names, commands }) {
    this.commands = commands;
    this.robotsBox = robots;
    this.zonesBox = zones;
    this.status = status;
    this.note = note;
    this.interactions = interactions;
    this.onSelect = onSelect;
    this.names = names;
    /** @type {string | null} */
    this.selected = null;
    // "Any robot" chosen: a zone sends whichever robot the dispatcher picks.
    this.anyRobot = false;
    /** @type {HTMLButtonElement | null} */
    this.anyButton = null;
    this.ordersAllowed = true;
    // Whether the person at the page may send robots at all (a viewer may not).
    this.commandsAllowed = true;
    /** Per command id, what the status line says about it. @type {Map<string, string>} */
    this.pending = new Map();
    /** @type {FleetView | null} */
    this.fleet = null;
    /** @type {Map<string, {made: HTMLButtonElement, dot: HTMLSpanElement}>} */
    this.robotButtons = new Map();
    /** @type {Map<string, HTMLButtonElement>} */
    this.zoneButtons = new Map();
    stopAll.addEventListener("click", () => this.stopAll());
    weather.addEventListener("click", () => this.askWeather());
    this.weatherButton = weather;
    document.addEventListener("keydown", (event) => this.onKey(event));
  }

  /** @param {FleetView} fleet */
  build(fleet) {
    this.fleet = fleet;
    this.robotButtons = new Map();
    this.zoneButtons = new Map();
    this.robotsBox.replaceChildren();
    this.zonesBox.replaceChildren();
    for (const robot of fleet.robots) {
      if (!robot.key) continue;
      const made = button(undefined);
      const dot = document.createElement("span");
      dot.className = "robot-dot";
      made.append(key(robot.key), dot, document.createTextNode(robot.name));
      made.setAttribute("aria-pressed", "false");
      made.dataset.thing = robot.thing;
      made.addEventListener("click", () => this.onSelect(robot.thing));
      this.robotsBox.appendChild(made);
      this.robotButtons.set(robot.thing, { made, dot });
    }
    const any = button(undefined);
    any.append(key(ANY.key), document.createTextNode(ANY.label));
    any.dataset.any = "true";
    any.setAttribute("aria-pressed", "false");
    any.addEventListener("click", () => this.chooseAny());
    any.hidden = !this.commandsAllowed;
    this.robotsBox.appendChild(any);
    this.anyButton = any;
    if (fleet.robots.length > this.robotButtons.size) {
      const select = document.createElement("select");
      select.className = "robot-select";
      select.setAttribute("aria-label", t("Any robot"));
      select.appendChild(new Option(t("All {count} robots…", { count: fleet.robots.length.toLocaleString("en-US") }), ""));
      for (const robot of fleet.robots) select.appendChild(new Option(robot.name, robot.thing));
      select.addEventListener("change", () => { if (select.value) this.onSelect(select.value); });
      this.robotsBox.appendChild(select);
    }
    for (const zone of fleet.zones) {
      // A one-letter zone's button is its key cap; others say their name beside it.
      const letter = zone.id.length === 1 && zone.key === zone.id;
      const made = button(undefined, letter ? "btn btn-key" : "btn");
      if (zone.key) made.appendChild(key(zone.key));
      if (!letter) made.appendChild(document.createTextNode(zoneLabel(zone)));
      made.setAttribute("aria-label", zoneLabel(zone));
      made.dataset.zone = zone.id;
      made.addEventListener("click", () => this.navigate(this.selected, zone.id));
      this.zonesBox.appendChild(made);
      this.zoneButtons.set(zone.id, made);
    }
    // The keys this fleet answers to (not a fixed "1–9, A–D, L"), unless a session's note shows.
    if (this.note.dataset.session !== "true") this.note.replaceChildren(...keysHint(fleet));
    this.refresh();
  }

  /** @param {string} thing @param {string} status */
  colour(thing, status) {
    const parts = this.robotButtons?.get(thing);
    if (parts) parts.dot.style.background = `var(--${statusColour(status)})`;
  }

  // "Any robot" on (or off again); a robot selected is let go.
  chooseAny() {
    const on = !this.anyRobot;
    if (this.selected) this.onSelect(this.selected);
    this.anyRobot = on;
    this.anyButton?.setAttribute("aria-pressed", String(on));
    if (on) this.tell(ANY.select);
    this.refresh();
  }

  /** @param {string | null} thing */
  select(thing) {
    this.selected = thing;
    if (thing && this.anyRobot) {
      this.anyRobot = false;
      this.anyButton?.setAttribute("aria-pressed", "false");
    }
    for (const [name, { made }] of this.robotButtons) made.setAttribute("aria-pressed", String(name === thing));
    this.refresh();
  }

  // While a voice session runs, orders are given by voice: the panel only selects and stops.
  /** @param {boolean} allowed @param {string | null} note */
  allowOrders(allowed, note) {
    this.ordersAllowed = allowed;
    this.note.dataset.session = note ? "true" : "false";
    if (note) this.note.textContent = note;
    else if (this.fleet) this.note.replaceChildren(...keysHint(this.fleet));
    this.refresh();
  }

  // A person whose role does not let them send robots: the panel selects and stops only.
  /** @param {boolean} allowed */
  allowCommands(allowed) {
    this.commandsAllowed = allowed;
    if (this.anyButton) this.anyButton.hidden = !allowed;
    if (!allowed && this.anyRobot) this.chooseAny();
    this.refresh();
  }

  refresh() {
    for (const made of this.zoneButtons?.values() ?? []) {
      made.disabled = !(this.selected || this.anyRobot) || !this.ordersAllowed || !this.commandsAllowed;
      const zone = made.dataset.zone;
      const name = zoneText(zone ?? "");
      made.title = this.selected ? t("Send {robot} to {zone}", { robot: this.names[this.selected], zone: name }) : this.anyRobot ? ANY.title(name) : t("{zone}: select a robot first", { zone: name });
    }
  }

  /** @param {string} message */
  tell(message, bad = false) {
    this.status.textContent = message;
    this.status.classList.toggle("error", bad);
  }

  // -- orders --------------------------------------------------------------------------

  /** @param {{robot: string, action: string, zone: string}} body @param {string} describe */
  async order(body, describe) {
    /** @type {Promise<CommandReply>} */
    const sent = post("/api/command", body);
    const result = sent.then((answer) => ({ commands: [answer.id] }), (err) => ({ error: err.message }));
    this.interactions.attach(result);
    this.tell(`${describe}…`);
    try {
      const { id } = await sent;
      this.pending.set(id, describe);
      this.tell(t("{what}: sent, waiting for the robot.", { what: describe }));
      // The robot may have answered before the station did.
      for (const [thing, ack] of Object.entries(this.commands[id]?.acks || {})) this.acknowledged(id, thing, ack);
      return id;
    } catch (err) {
      this.tell(reason(err), true);
      return null;
    }
  }

  /** @param {string | null} thing @param {string} zone */
  navigate(thing, zone) {
    if (!this.commandsAllowed) return;
    if (!thing && this.anyRobot) return this.ordersAllowed ? this.sendAny(zone) : undefined;
    if (!thing) {
      this.tell(t("Select a robot first: click it on the map, or press its number."), true);
      return;
    }
    if (!this.ordersAllowed) return;
    return this.order({ robot: thing, action: "navigate", zone }, t("{robot} to {zone}", { robot: this.names[thing], zone: zoneText(zone) }));
  }

  // Ask the assistant to send a robot to `zone`, as a person would say it.
  /** @param {string} zone */
  async sendAny(zone) {
    const spoken = this.fleet?.zones.find((z) => z.id === zone)?.name ?? `zone ${zone}`;
    /** @type {Promise<SayReply>} */
    const sent = post("/api/say", { utterance: ANY.utterance(spoken), origin: "station" });
    this.interactions.attach(sent.then(
      (turn) => ({ speech: turn.speech, intent: turn.intent, commands: turn.commands || [] }),
      (err) => ({ error: err.message }),
    ));
    this.tell(`${t("{robot} to {zone}", { robot: ANY.label, zone: zoneText(zone) })}…`);
    try {
      const turn = await sent;
      this.tell(t("The assistant: “{speech}”", { speech: turn.speech }));
    } catch (err) {
      this.tell(reason(err), true);
    }
  }

  async stopAll() {
    /** @type {Promise<CommandReply>} */
    const sent = post("/api/stop", {});
    this.interactions.attach(sent.then((answer) => ({ commands: [answer.id] }), (err) => ({ error: err.message })));
    try {
      const { id } = await sent;
      this.pending.set(id, t("Stop all"));
      this.tell(t("Stop all: sent."));
    } catch (err) {
      this.tell(reason(err), true);
    }
  }

  async askWeather() {
    this.weatherButton.disabled = true;
    /** @type {Promise<SayReply>} */
    const sent = post("/api/say", { utterance: said("what is the weather"), origin: "station-weather" });
    this.interactions.attach(sent.then(
      (turn) => ({ asks: true, speech: turn.speech, intent: turn.intent, commands: turn.commands || [] }),
      (err) => ({ asks: true, error: err.message }),
    ));
    this.tell(t("Asking the assistant for the weather…"));
    try {
      const turn = await sent;
      this.tell(t("The assistant: “{speech}”", { speech: turn.speech }));
      const { speak } = await import("./api.js");
      await speak(turn.speech);
    } catch (err) {
      this.tell(reason(err), true);
    } finally {
      this.weatherButton.disabled = false;
    }
  }

  // A robot acknowledged (or rejected) a command this panel sent.
  /** @param {string} id @param {string} thing @param {Acknowledgment} ack */
  acknowledged(id, thing, ack) {
    const describe = this.pending.get(id);
    if (!describe) return;
    const name = this.names[thing] || thing;
    if (ack.event === "rejected") this.tell(t("{what}: {robot} rejected it.", { what: describe, robot: name }), true);
    else this.tell(t("{what}: acknowledged by {robot} in {ms} ms.", { what: describe, robot: name, ms: Math.round(ack.latency_ms) }));
  }

  /** @param {KeyboardEvent} event */
  onKey(event) {
    if (event.repeat || event.ctrlKey || event.metaKey || event.altKey || typing(event.target)) return;
    if (event.key === "Escape") {
      event.preventDefault();
      this.stopAll();
      return;
    }
    if (event.key === ANY.key) {
      event.preventDefault();
      if (this.commandsAllowed) this.chooseAny();
      return;
    }
    const robot = this.fleet?.robots.find((r) => r.key && r.key === event.key);
    if (robot) {
      event.preventDefault();
      this.onSelect(robot.thing);
      return;
    }
    const zone = this.fleet?.zones.find((z) => z.key && z.key.toLowerCase() === event.key.toLowerCase());
    if (zone) {
      event.preventDefault();
      this.navigate(this.selected, zone.id);
    }
  }
}

// "Zone A" for a one-letter zone, else its spoken name with a capital ("Loading zone").
/** @param {ZoneEntry} zone */
export function zoneLabel(zone) {
  if (zone.id.length === 1) return t("Zone {id}", { id: zone.id });
  return zone.name.charAt(0).toUpperCase() + zone.name.slice(1);
}
