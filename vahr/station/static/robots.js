// The robots panel: per robot its presence, status, zone, cargo, the command under way with
// its progress, the last result with its reason, and the reported shadow on demand.

import { describe, statusColour, zoneText } from "./map.js";

const time = (ms) => (ms ? new Date(ms).toLocaleTimeString([], { hour: "2-digit", minute: "2-digit", second: "2-digit" }) : "never");

function text(tag, className, content) {
  const node = document.createElement(tag);
  if (className) node.className = className;
  if (content !== undefined) node.textContent = content;
  return node;
}

export class RobotsPanel {
  constructor(list, { onSelect }) {
    this.list = list;
    this.onSelect = onSelect;
    this.rows = new Map();
  }

  build(fleet) {
    this.list.replaceChildren();
    this.rows.clear();
    fleet.robots.forEach((robot, index) => {
      const row = text("li", "robot-row");
      row.dataset.thing = robot.thing;
      const badge = text("button", "badge", robot.key ?? String(index + 1));
      badge.type = "button";
      badge.title = `Select ${robot.name}`;
      badge.setAttribute("aria-label", `Select ${robot.name}`);
      badge.addEventListener("click", () => this.onSelect(robot.thing));
      const name = text("span", "name", robot.name);
      const presence = text("span", "presence");
      const facts = text("div", "facts");
      const task = text("div", "task");
      const last = text("div", "last");
      const details = text("details");
      const summary = text("summary", "", "Reported shadow");
      const raw = text("pre");
      details.append(summary, raw);
      row.append(badge, name, presence, facts, task, last, details);
      this.list.appendChild(row);
      this.rows.set(robot.thing, { row, badge, presence, facts, task, last, raw, name: robot.name });
    });
  }

  select(thing) {
    for (const [name, parts] of this.rows) parts.row.classList.toggle("selected", name === thing);
  }

  update(thing, robot, commands) {
    const parts = this.rows.get(thing);
    if (!parts) return;
    const reported = robot.reported || {};
    const online = robot.online;
    const status = online === false ? "offline" : reported.status || "idle";
    parts.row.dataset.status = status;
    parts.badge.style.background = `var(--${statusColour(status)})`;
    parts.presence.replaceChildren(text("span", "dot"), text("span", "", online ? "online" : online === false ? `offline · seen ${time(robot.last_seen)}` : "not heard yet"));
    parts.presence.classList.toggle("online", Boolean(online));

    const facts = [
      ["", text("span", "status-text", describe({ status, reported, lastSeen: robot.last_seen, progress: robot.progress }, { where: false }))],
      ["zone ", text("b", "", reported.zone ? zoneText(reported.zone) : "—")],
    ];
    parts.facts.replaceChildren();
    for (const [label, value] of facts) {
      const span = text("span", "", label);
      span.appendChild(value);
      parts.facts.appendChild(span);
    }
    parts.facts.appendChild(reported.cargo ? text("span", "cargo-tag", "package") : text("span", "", "no package"));
    parts.facts.querySelector(".status-text").style.color = `var(--${statusColour(status)})`;

    const last = reported.last_command;
    parts.task.replaceChildren();
    if (reported.task) {
      const command = last ? commands[last.id] : null;
      const where = reported.destination ? ` → ${zoneText(reported.destination)}` : "";
      parts.task.appendChild(text("span", "task-what", `${reported.task}${where}`));
      const fraction = robot.progress?.progress;
      if (status === "navigating" && fraction !== undefined && fraction !== null) {
        const bar = text("span", "progress");
        const fill = text("span");
        fill.style.width = `${Math.round(fraction * 100)}%`;
        bar.appendChild(fill);
        parts.task.append(bar, text("span", "", `${Math.round(fraction * 100)}%`));
      }
      if (command?.source) parts.task.appendChild(text("span", "tag", `by ${shortSource(command.source)}`));
    }
    if (last) {
      const reason = last.reason ? `: ${last.reason}` : "";
      parts.last.textContent = `Last: ${last.action} ${last.result}${reason}`;
      parts.last.classList.toggle("bad", ["rejected", "failed"].includes(last.result));
    } else {
      parts.last.textContent = "Last: no command yet";
      parts.last.classList.remove("bad");
    }
    parts.raw.textContent = JSON.stringify(reported, null, 2);
  }
}

export function sourceName(source) {
  if (source === "alexa") return "the assistant";
  if (source === "console") return "keyboard and mouse";
  if (source.startsWith("robot:")) return source.slice(6);
  return source;
}

function shortSource(source) {
  if (source === "alexa") return "voice";
  if (source === "console") return "keyboard";
  return sourceName(source);
}
