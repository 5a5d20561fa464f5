// @ts-check
// The robots panel: per robot its presence, status, zone, cargo, the command under way with
// its progress, the last result with its reason, and the reported shadow on demand.
//
// Each row is built once; an update only rewrites the text that changed, so a hundred
// robots reporting progress stay cheap to draw.

import { clock, node } from "./dom.js";
import { describe, statusColour, zoneText } from "./map.js";

/** @import { CommandMessage, FleetView, Reported, RobotView } from "./contract.js" */

// Up to this many robots the list is as tall as its rows; beyond, it has the card's whole
// height whatever its rows say, so a row that changes lays out the list alone, not the page.
const ROWS_SIZED_BY_CONTENT = 4;

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
  /** @param {HTMLElement} list @param {{onSelect: (thing: string) => void}} handlers */
  constructor(list, { onSelect }) {
    this.list = list;
    this.onSelect = onSelect;
    /** @type {Map<string, Row>} */
    this.rows = new Map();
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
    this.list.replaceChildren();
    this.list.classList.toggle("many", fleet.robots.length > ROWS_SIZED_BY_CONTENT);
    this.rows.clear();
    fleet.robots.forEach((robot, index) => {
      const row = node("li", "robot-row");
      row.dataset.thing = robot.thing;
      const badge = node("button", "badge", robot.key ?? String(index + 1));
      badge.type = "button";
      badge.title = `Select ${robot.name}`;
      badge.setAttribute("aria-label", `Select ${robot.name}`);
      badge.addEventListener("click", () => this.onSelect(robot.thing));
      const presence = node("span", "presence");
      const presenceText = node("span");
      presence.append(node("span", "dot"), presenceText);
      const facts = node("div", "facts");
      const status = node("span", "status-text");
      const zone = node("b");
      const zoneFact = node("span", "", "zone ");
      zoneFact.appendChild(zone);
      const cargo = node("span");
      facts.append(status, zoneFact, cargo);
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
      details.append(node("summary", "", "Reported shadow"), raw);
      // The raw shadow is written only while someone looks at it.
      details.addEventListener("toggle", () => { if (details.open) raw.textContent = JSON.stringify(parts.reported, null, 2); });
      row.append(badge, node("span", "name", robot.name), presence, facts, task, last, details);
      this.list.appendChild(row);
      const parts = { row, badge, presence, presenceText, status, zone, cargo, task, taskWhat, bar, fill, percent, source, last, details, raw, reported: {} };
      this.rows.set(robot.thing, parts);
    });
  }

  /** @param {string | null} thing */
  select(thing) {
    for (const [name, parts] of this.rows) parts.row.classList.toggle("selected", name === thing);
  }

  /** @param {string} thing @param {RobotView} robot @param {Record<string, CommandMessage>} commands */
  update(thing, robot, commands) {
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
    put(parts.presenceText, "textContent", online ? "online" : online === false ? `offline · seen ${clock(robot.last_seen, "never")}` : "not heard yet");
    parts.presence.classList.toggle("online", Boolean(online));
    put(parts.status, "textContent", describe({ status, reported, lastSeen: robot.last_seen, progress: robot.progress }, { where: false }));
    put(parts.status.style, "color", colour);
    put(parts.zone, "textContent", reported.zone ? zoneText(reported.zone) : "—");
    put(parts.cargo, "textContent", reported.cargo ? "package" : "no package");
    put(parts.cargo, "className", reported.cargo ? "cargo-tag" : "");

    const last = reported.last_command;
    const working = Boolean(reported.task);
    parts.task.hidden = !working;
    if (working) {
      put(parts.taskWhat, "textContent", `${reported.task}${reported.destination ? ` → ${zoneText(reported.destination)}` : ""}`);
      const fraction = robot.progress?.progress;
      const driving = status === "navigating" && fraction !== undefined && fraction !== null;
      parts.bar.hidden = parts.percent.hidden = !driving;
      if (driving) {
        put(parts.fill.style, "width", `${Math.round(fraction * 100)}%`);
        put(parts.percent, "textContent", `${Math.round(fraction * 100)}%`);
      }
      const command = last ? commands[last.id] : null;
      parts.source.hidden = !command?.source;
      if (command?.source) put(parts.source, "textContent", `by ${shortSource(command.source)}`);
    }
    if (last) {
      put(parts.last, "textContent", `Last: ${last.action} ${last.result}${last.reason ? `: ${last.reason}` : ""}`);
      parts.last.classList.toggle("bad", ["rejected", "failed"].includes(last.result));
    } else {
      put(parts.last, "textContent", "Last: no command yet");
    }
    if (parts.details.open) put(parts.raw, "textContent", JSON.stringify(reported, null, 2));
  }
}

/** Who sent a command, in words. @param {string} source */
export function sourceName(source) {
  if (source === "alexa") return "the assistant";
  if (source === "console") return "keyboard and mouse";
  if (source.startsWith("robot:")) return source.slice(6);
  return source;
}

/** @param {string} source */
function shortSource(source) {
  if (source === "alexa") return "voice";
  if (source === "console") return "keyboard";
  return sourceName(source);
}
