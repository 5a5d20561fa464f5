// @ts-check
// The robots panel: per robot its presence, status, zone, cargo, the command under way with
// its progress, the last result with its reason, and the reported shadow on demand.
//
// Each row is built once; an update only rewrites the text that changed, so a hundred
// robots reporting progress stay cheap to draw. A larger fleet gets one line per robot in a
// virtualized list (virtual-list.js): elements only for the rows in view.
//
// The search box above finds robots by spoken or thing name and narrows them by status and
// zone (search.js); the list shows the matches, best first, and a click on one selects it.

import { clock, node } from "./dom.js";
import { t } from "./i18n.js";
import { describe, reasonSaid, statusColour, zoneText } from "./map.js";
import { findRobots } from "./search.js";
import { VirtualList } from "./virtual-list.js";

/** @import { CommandMessage, FleetView, Reported, RobotView } from "./contract.js" */

// Up to this many robots the list is as tall as its rows; beyond, it has the card's whole
// height whatever its rows say, so a row that changes lays out the list alone, not the page.
const ROWS_SIZED_BY_CONTENT = 4;
// More robots than this are listed one line each, virtualized.
export const FULL_ROWS_UP_TO = 24;
// A one-line row's height in pixels (station.css, .robot-row.line).
const LINE_PX = 34;
// With a status or zone filter on, the matches are found again at most this often, so the
// list does not jump under the pointer as robots change.
const REFILTER_MS = 1000;

// The words this view shows (one place, for translation).
const WORDS = {
  none: t("No robot matches."),
  anyStatus: t("any status"),
  anyZone: t("any zone"),
  /** @param {number} shown @param {number} all */
  count: (shown, all) => (shown === all ? t("{all} robots", { all }) : t("{shown} of {all} robots", { shown, all })),
  /** @param {string} name */
  select: (name) => t("Select {name}", { name }),
};
// The statuses a search can ask for, in the legend's order.
const STATUSES = ["idle", "navigating", "loading", "unloading", "waiting", "stopped", "stuck", "error", "offline"];

/**
 * The search box and its filters.
 * @typedef {object} SearchParts
 * @property {HTMLInputElement} input
 * @property {HTMLSelectElement} status
 * @property {HTMLSelectElement} zone
 * @property {HTMLElement} none shown when nothing matches
 * @property {HTMLElement} count how many are listed
 */

/**
 * One line of the virtualized list.
 * @typedef {object} Line
 * @property {HTMLLIElement} row
 * @property {HTMLButtonElement} pick
 * @property {HTMLSpanElement} dot
 * @property {HTMLSpanElement} name
 * @property {HTMLSpanElement} status
 * @property {HTMLSpanElement} zone
 * @property {HTMLSpanElement} cargo
 * @property {HTMLSpanElement} battery
 * @property {HTMLSpanElement} service
 * @property {string | null} thing the robot it shows
 */

// Set a property only when it changes (reading is cheap, writing makes the browser work).
/**
 * @template {object} T
 * @template {keyof T} K
 * @param {T} target
 * @param {K} key
 * @param {T[K]} value
 */
function put(target, key, value) {
  if (target[key] !== value) target[key] = value;
}

/**
 * One robot's row and the parts of it an update rewrites.
 * @typedef {object} Row
 * @property {HTMLLIElement} row
 * @property {HTMLButtonElement} badge
 * @property {HTMLSpanElement} presence
 * @property {HTMLSpanElement} presenceText
 * @property {HTMLSpanElement} status
 * @property {HTMLElement} zone
 * @property {HTMLSpanElement} cargo
 * @property {HTMLSpanElement} battery
 * @property {HTMLSpanElement} service
 * @property {HTMLDivElement} task
 * @property {HTMLSpanElement} taskWhat
 * @property {HTMLSpanElement} bar
 * @property {HTMLSpanElement} fill
 * @property {HTMLSpanElement} percent
 * @property {HTMLSpanElement} source
 * @property {HTMLDivElement} last
 * @property {HTMLDetailsElement} details
 * @property {HTMLPreElement} raw
 * @property {Reported} reported
 */

export class RobotsPanel {
  /** @param {HTMLElement} list @param {{onSelect: (thing: string) => void, search: SearchParts}} handlers */
  constructor(list, { onSelect, search }) {
    this.list = list;
    this.onSelect = onSelect;
    this.search = search;
    /** @type {Map<string, Row>} */
    this.rows = new Map();
    /** The robots' names, in the fleet's order. @type {Array<{thing: string, name: string, index: number}>} */
    this.entries = [];
    /** @type {Map<string, string>} */
    this.names = new Map();
    /** What the search reads of each robot. @type {Map<string, {status: string, zone: string | null}>} */
    this.facts = new Map();
    /** @type {Map<string, RobotView>} */
    this.views = new Map();
    /** The robots listed, best match first. @type {string[]} */
    this.shown = [];
    /** @type {VirtualList<HTMLLIElement> | null} */
    this.lines = null;
    /** @type {Map<string, Line>} */
    this.bound = new Map();
    /** @type {string | null} */
    this.selected = null;
    /** The robots out of service. @type {Set<string>} */
    this.outOfService = new Set();
    /** Under this charge a robot is low (the fleet's). */
    this.chargeBelow = 20;
    /** @type {ReturnType<typeof setTimeout> | null} */
    this.refilter = null;
    search.none.textContent = WORDS.none;
    search.status.replaceChildren(new Option(WORDS.anyStatus, ""), ...STATUSES.map((status) => new Option(t(status), status)));
    const find = () => this.find();
    search.input.addEventListener("input", find);
    search.status.addEventListener("change", find);
    search.zone.addEventListener("change", find);
    // Enter in the search box selects the best match.
    search.input.addEventListener("keydown", (event) => {
      if (event.key === "Enter" && this.shown.length) {
        event.preventDefault();
        this.onSelect(this.shown[0]);
      }
    });
  }

  // List the robots that match the search now.
  find() {
    if (this.refilter !== null) clearTimeout(this.refilter);
    this.refilter = null;
    const findable = this.entries.map(({ thing, name }) => ({ thing, name, ...(this.facts.get(thing) || { status: "idle", zone: null }) }));
    this.shown = findRobots(findable, { text: this.search.input.value, status: this.search.status.value, zone: this.search.zone.value });
    this.search.none.hidden = this.shown.length > 0;
    this.search.count.textContent = WORDS.count(this.shown.length, this.entries.length);
    if (this.lines) {
      this.lines.setCount(this.shown.length);
    } else {
      const listed = new Set(this.shown);
      for (const [thing, parts] of this.rows) parts.row.hidden = !listed.has(thing);
      // Best match first.
      for (const thing of this.shown) {
        const row = this.rows.get(thing)?.row;
        if (row) this.list.appendChild(row);
      }
    }
  }

  /** The robots taken out of service (the dispatcher's list). @param {string[]} things */
  setOutOfService(things) {
    this.outOfService = new Set(things);
    for (const [thing, parts] of this.rows) {
      const out = this.outOfService.has(thing);
      parts.row.classList.toggle("out-of-service", out);
      parts.service.hidden = !out;
    }
    for (const line of this.bound.values()) this.fillLine(line);
  }

  // The robots with an open alert: their rows are marked until it is acknowledged.
  /** @param {Map<string, string>} troubled */
  setTroubled(troubled) {
    for (const [thing, { row }] of this.rows) {
      const trouble = troubled.get(thing);
      row.classList.toggle("alerting", Boolean(trouble));
      if (trouble) row.dataset.trouble = trouble;
    }
  }

  /** @param {FleetView} fleet */
  build(fleet) {
    this.chargeBelow = fleet.charge_below ?? 20;
    this.list.replaceChildren();
    this.list.classList.toggle("many", fleet.robots.length > ROWS_SIZED_BY_CONTENT);
    this.rows.clear();
    this.bound.clear();
    this.entries = fleet.robots.map((robot, index) => ({ thing: robot.thing, name: robot.name, index }));
    this.names = new Map(fleet.robots.map((robot) => [robot.thing, robot.name]));
    this.search.zone.replaceChildren(new Option(WORDS.anyZone, ""), ...fleet.zones.map((zone) => new Option(zone.name, zone.id)));
    this.lines = null;
    if (fleet.robots.length > FULL_ROWS_UP_TO) {
      this.list.classList.add("lines");
      this.lines = new VirtualList(this.list, LINE_PX, { make: () => this.makeLine(), bind: (row, index) => this.bindLine(row, index) });
      this.find();
      return;
    }
    this.list.classList.remove("lines");
    fleet.robots.forEach((robot, index) => {
      const row = node("li", "robot-row");
      row.dataset.thing = robot.thing;
      const badge = node("button", "badge", robot.key ?? String(index + 1));
      badge.type = "button";
      badge.title = WORDS.select(robot.name);
      badge.setAttribute("aria-label", WORDS.select(robot.name));
      badge.addEventListener("click", () => this.onSelect(robot.thing));
      const presence = node("span", "presence");
      const presenceText = node("span");
      presence.append(node("span", "dot"), presenceText);
      const facts = node("div", "facts");
      const status = node("span", "status-text");
      const zone = node("b");
      const zoneFact = node("span", "", t("zone") + " ");
      zoneFact.appendChild(zone);
      const cargo = node("span");
      const battery = node("span", "battery");
      battery.hidden = true;
      const service = node("span", "service-tag", t("out of service"));
      service.hidden = !this.outOfService.has(robot.thing);
      facts.append(status, zoneFact, cargo, battery, service);
      const task = node("div", "task");
      const taskWhat = node("span", "task-what");
      const bar = node("span", "progress");
      const fill = node("span");
      bar.appendChild(fill);
      const percent = node("span");
      const source = node("span", "tag");
      task.append(taskWhat, bar, percent, source);
      const last = node("div", "last");
      const details = node("details");
      const raw = node("pre");
      details.append(node("summary", "", t("Reported shadow")), raw);
      // The raw shadow is written only while someone looks at it.
      details.addEventListener("toggle", () => { if (details.open) raw.textContent = JSON.stringify(parts.reported, null, 2); });
      row.append(badge, node("span", "name", robot.name), presence, facts, task, last, details);
      this.list.appendChild(row);
      row.classList.toggle("out-of-service", this.outOfService.has(robot.thing));
      const parts = { row, badge, presence, presenceText, status, zone, cargo, battery, service, task, taskWhat, bar, fill, percent, source, last, details, raw, reported: {} };
      this.rows.set(robot.thing, parts);
    });
    this.find();
  }

  // -- one line per robot (a large fleet) -------------------------------------------------

  /** @returns {HTMLLIElement} */
  makeLine() {
    const row = node("li", "robot-row line");
    const pick = node("button", "line-pick");
    pick.type = "button";
    const dot = node("span", "line-dot"), name = node("span", "name"), status = node("span", "status-text");
    const zone = node("span", "line-zone"), cargo = node("span", "cargo-tag");
    const battery = node("span", "battery"), service = node("span", "service-tag", t("out of service"));
    pick.append(dot, name, status, zone, cargo, battery, service);
    row.appendChild(pick);
    /** @type {Line} */
    const line = { row, pick, dot, name, status, zone, cargo, battery, service, thing: null };
    pick.addEventListener("click", () => { if (line.thing) this.onSelect(line.thing); });
    lineOf.set(row, line);
    return row;
  }

  /** @param {HTMLLIElement} row @param {number} index */
  bindLine(row, index) {
    const line = lineOf.get(row);
    const thing = this.shown[index];
    if (!line || !thing) return;
    if (line.thing !== thing) {
      if (line.thing && this.bound.get(line.thing) === line) this.bound.delete(line.thing);
      line.thing = thing;
      this.bound.set(thing, line);
      const name = this.names.get(thing) ?? thing;
      put(line.name, "textContent", name);
      line.pick.setAttribute("aria-label", WORDS.select(name));
      row.dataset.thing = thing;
    }
    this.fillLine(line);
  }

  /** @param {Line} line */
  fillLine(line) {
    if (!line.thing) return;
    const robot = this.views.get(line.thing);
    /** @type {Reported} */
    const reported = robot?.reported || {};
    const status = robot?.online === false ? "offline" : reported.status || "idle";
    if (line.row.dataset.status !== status) line.row.dataset.status = status;
    line.row.classList.toggle("selected", line.thing === this.selected);
    put(line.dot.style, "background", `var(--${statusColour(status)})`);
    put(line.status, "textContent", robot ? describe({ status, reported, lastSeen: robot.last_seen, progress: robot.progress }, { where: false }) : status);
    put(line.status.style, "color", `var(--${statusColour(status)})`);
    put(line.zone, "textContent", reported.zone ? zoneText(reported.zone) : "");
    line.cargo.hidden = !reported.cargo;
    if (reported.cargo) put(line.cargo, "textContent", t("package"));
    this.showBattery(line.battery, reported.battery);
    const out = this.outOfService.has(line.thing);
    line.service.hidden = !out;
    line.row.classList.toggle("out-of-service", out);
  }

  /** A robot's charge, and whether it charges; red under the fleet's threshold.
   * @param {HTMLElement} element @param {Reported["battery"]} battery */
  showBattery(element, battery) {
    element.hidden = !battery;
    if (!battery) return;
    const words = battery.charging ? t("battery {percent}%, charging", { percent: battery.percent }) : t("battery {percent}%", { percent: battery.percent });
    put(element, "textContent", words);
    element.classList.toggle("low", battery.percent < this.chargeBelow && !battery.charging);
    element.classList.toggle("charging", Boolean(battery.charging));
  }

  /** @param {string | null} thing */
  select(thing) {
    this.selected = thing;
    for (const [name, parts] of this.rows) parts.row.classList.toggle("selected", name === thing);
    if (this.lines) {
      for (const line of this.bound.values()) line.row.classList.toggle("selected", line.thing === thing);
      const index = thing ? this.shown.indexOf(thing) : -1;
      if (index >= 0) this.lines.show(index);
    }
  }

  /** @param {string} thing @param {RobotView} robot @param {Record<string, CommandMessage>} commands */
  update(thing, robot, commands) {
    /** @type {Reported} */
    const state = robot.reported || {};
    const before = this.facts.get(thing);
    const facts = { status: robot.online === false ? "offline" : state.status || "idle", zone: state.zone ?? null };
    this.facts.set(thing, facts);
    this.views.set(thing, robot);
    const filtered = this.search.status.value || this.search.zone.value;
    if (filtered && (before?.status !== facts.status || before?.zone !== facts.zone) && this.refilter === null) {
      this.refilter = setTimeout(() => this.find(), REFILTER_MS);
    }
    if (this.lines) {
      const line = this.bound.get(thing);
      if (line) this.fillLine(line);
      return;
    }
    const parts = this.rows.get(thing);
    if (!parts) return;
    /** @type {Reported} */
    const reported = robot.reported || {};
    parts.reported = reported;
    const online = robot.online;
    const status = online === false ? "offline" : reported.status || "idle";
    const colour = `var(--${statusColour(status)})`;
    if (parts.row.dataset.status !== status) parts.row.dataset.status = status;
    put(parts.badge.style, "background", colour);
    put(parts.presenceText, "textContent", online ? t("online") : online === false ? t("offline · seen {when}", { when: clock(robot.last_seen, t("never")) }) : t("not heard yet"));
    parts.presence.classList.toggle("online", Boolean(online));
    put(parts.status, "textContent", describe({ status, reported, lastSeen: robot.last_seen, progress: robot.progress }, { where: false }));
    put(parts.status.style, "color", colour);
    put(parts.zone, "textContent", reported.zone ? zoneText(reported.zone) : "—");
    put(parts.cargo, "textContent", reported.cargo ? t("package") : t("no package"));
    put(parts.cargo, "className", reported.cargo ? "cargo-tag" : "");
    this.showBattery(parts.battery, reported.battery);

    const last = reported.last_command;
    const working = Boolean(reported.task);
    parts.task.hidden = !working;
    if (working) {
      put(parts.taskWhat, "textContent", `${t(reported.task ?? "")}${reported.destination ? ` → ${zoneText(reported.destination)}` : ""}`);
      const fraction = robot.progress?.progress;
      const driving = status === "navigating" && fraction !== undefined && fraction !== null;
      parts.bar.hidden = parts.percent.hidden = !driving;
      if (driving) {
        put(parts.fill.style, "width", `${Math.round(fraction * 100)}%`);
        put(parts.percent, "textContent", `${Math.round(fraction * 100)}%`);
      }
      const command = last ? commands[last.id] : null;
      parts.source.hidden = !command?.source;
      if (command?.source) put(parts.source, "textContent", t("by {who}", { who: shortSource(command.source) }));
    }
    if (last) {
      // The reason names its zone by id; a person reads the zone's name.
      const why = last.reason ? `: ${reasonSaid(last.reason, last.zone)}` : "";
      put(parts.last, "textContent", t("Last: {action} {result}", { action: t(last.action), result: t(last.result) }) + why);
      parts.last.classList.toggle("bad", ["rejected", "failed"].includes(last.result));
    } else {
      put(parts.last, "textContent", t("Last: no command yet"));
    }
    if (parts.details.open) put(parts.raw, "textContent", JSON.stringify(reported, null, 2));
  }
}

/** The line each row element shows. @type {WeakMap<HTMLLIElement, Line>} */
const lineOf = new WeakMap();

/** Who sent a command, in words. @param {string} source */
export function sourceName(source) {
  if (source === "alexa") return t("the assistant");
  if (source === "console") return t("keyboard and mouse");
  if (source === "dispatcher") return t("the dispatcher");
  if (source.startsWith("robot:")) return source.slice(6);
  return source;
}

/** @param {string} source */
function shortSource(source) {
  if (source === "alexa") return t("voice");
  if (source === "console") return t("keyboard");
  return sourceName(source);
}
