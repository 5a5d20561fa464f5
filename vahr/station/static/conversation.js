// @ts-check
// The conversation: every exchange with the assistant in order (what was said or heard,
// the intent and slots understood, the reply, the commands it sent and how fast the robots
// acknowledged them), the orders from the keyboard and mouse, and the robots' own
// exchanges with the assistant. Filterable by robot.

import { clock, node } from "./dom.js";
import { zoneText } from "./map.js";
import { sourceName } from "./robots.js";
import { CONVERSATION_LIMIT } from "./contract.js";
import { t } from "./i18n.js";

/** @import { AnnouncementMessage, CommandMessage, ConversationEntry, EventMessage, FleetView, TurnMessage } from "./contract.js" */

/** @type {Record<string, string>} */
const ORIGINS = {
  "station-voice": t("You, by voice"),
  station: t("You, typed"),
  "station-weather": t("Weather button"),
  say: "vahr say",
  console: t("Console"),
};
const FALLBACK = "AMAZON.FallbackIntent";
const ENTRIES_KEPT = CONVERSATION_LIMIT; // as many as the station keeps for a new page


/** @param {string} text */
function quoted(text) {
  const q = node("q", "", text);
  return q;
}

export class Conversation {
  /**
   * @param {HTMLElement} list
   * @param {HTMLElement} filters
   * @param {{commands: Record<string, CommandMessage>, names: Record<string, string>}} shared
   *   the commands seen by id and the robots' spoken names (the page's store)
   */
  constructor(list, filters, { commands, names }) {
    this.list = list;
    this.filters = filters;
    this.commands = commands;
    this.names = names;
    /** @type {string | null} */
    this.filter = null;
    /** Per command id, the functions that redraw what shows it. @type {Map<string, Array<() => void>>} */
    this.refreshers = new Map();
    /** Commands acknowledged since the last frame. @type {Set<string>} */
    this.stale = new Set();
    /** @type {number | null} */
    this.frame = null;
    // The list follows the newest entry while the reader is at its end, and stays where
    // the reader scrolled to otherwise: entries never pull the text away from them.
    this.sticky = true;
    list.addEventListener("scroll", () => {
      this.sticky = list.scrollHeight - list.scrollTop - list.clientHeight < 40;
    });
    // Following happens when the list or an entry has been laid out anew (an entry
    // appeared or grew), so it never makes the browser lay the page out an extra time:
    // a fleet command's hundred acknowledgments cost one layout, not a hundred.
    this.resized = new ResizeObserver(() => this.follow());
    this.resized.observe(list);
  }

  follow() {
    if (this.sticky) this.list.scrollTop = this.list.scrollHeight;
  }

  // Acknowledgments come in bursts: what shows them is redrawn once, in the next frame.
  redrawStale() {
    this.frame = null;
    for (const commandId of this.stale) for (const redraw of this.refreshers.get(commandId) || []) redraw();
    this.stale.clear();
  }

  /** @param {FleetView} fleet @param {ConversationEntry[]} entries */
  build(fleet, entries) {
    this.list.replaceChildren();
    this.resized.disconnect();
    this.resized.observe(this.list);
    this.refreshers.clear();
    this.filters.replaceChildren();
    /** @type {Array<[string | null, string]>} */
    const chips = [[null, t("All")], ...fleet.robots.slice(0, 8).map((r) => /** @type {[string, string]} */ ([r.thing, r.name]))];
    for (const [thing, label] of chips) {
      const chip = node("button", "chip", label);
      chip.type = "button";
      chip.setAttribute("aria-pressed", String(thing === this.filter));
      chip.addEventListener("click", () => this.setFilter(thing));
      chip.dataset.thing = thing ?? "";
      this.filters.appendChild(chip);
    }
    for (const entry of entries) this.add(entry);
    this.showEmpty();
    this.sticky = true;
    this.follow();
  }

  /** @param {string | null} thing */
  setFilter(thing) {
    this.filter = thing;
    for (const chip of this.filters.children) chip.setAttribute("aria-pressed", String((chip.getAttribute("data-thing") || null) === thing));
    for (const item of this.entries()) item.hidden = !this.visible(item);
    this.showEmpty();
    this.sticky = true;
    this.follow();
  }

  entries() {
    return /** @type {NodeListOf<HTMLElement>} */ (this.list.querySelectorAll(".entry"));
  }

  /** @param {HTMLElement} item */
  visible(item) {
    return this.filter === null || (item.dataset.robots || "").split(" ").includes(this.filter);
  }

  showEmpty() {
    const shown = [...this.entries()].some((item) => !item.hidden);
    let empty = this.list.querySelector(".empty");
    if (shown && empty) empty.remove();
    if (!shown && !empty) {
      empty = node("li", "empty", this.filter ? t("Nothing with this robot yet.") : t("Nothing said yet. Hold “Hold to talk”, type below, or use vahr say."));
      this.list.appendChild(empty);
    }
  }

  // One conversation message from the feed (turn, command, or a robot's exchange event).
  /** @param {ConversationEntry} message */
  add(message) {
    let item = null;
    if (message.type === "turn") item = this.turn(message);
    else if (message.type === "command") item = this.command(message);
    else if (message.type === "event") item = this.exchange(message);
    else if (message.type === "announcement") item = this.announcement(message);
    if (!item) return;
    item.dataset.robots = (message.robots || []).join(" ");
    item.hidden = !this.visible(item);
    this.list.querySelector(".empty")?.remove();
    this.list.appendChild(item);
    this.resized.observe(item);
    // The oldest entries go, so a long session does not grow the page without end.
    for (let oldest = this.list.firstElementChild; oldest && this.list.children.length > ENTRIES_KEPT; oldest = this.list.firstElementChild) {
      this.resized.unobserve(oldest);
      oldest.remove();
    }
    this.showEmpty();
  }

  /** @param {string} commandId */
  acknowledged(commandId) {
    this.stale.add(commandId);
    if (this.frame === null) this.frame = requestAnimationFrame(() => this.redrawStale());
  }

  /** @param {string} commandId @param {() => void} redraw */
  watch(commandId, redraw) {
    const redraws = this.refreshers.get(commandId) ?? [];
    this.refreshers.set(commandId, redraws);
    redraws.push(redraw);
    // Acknowledgments come within seconds: the oldest commands' redraws can go.
    for (const oldest of this.refreshers.keys()) {
      if (this.refreshers.size <= ENTRIES_KEPT) break;
      this.refreshers.delete(oldest);
    }
    redraw();
  }

  /** @param {string} commandId */
  commandLine(commandId) {
    const command = this.commands[commandId];
    if (!command) return t("command {id}", { id: commandId.slice(0, 8) });
    const zone = command.params?.zone ? ` → ${zoneText(command.params.zone)}` : "";
    const who = command.target === "fleet" ? t("every robot") : this.names[command.target] || command.target;
    const acks = Object.entries(command.acks || {});
    let how = t("waiting for an acknowledgment");
    if (acks.length) {
      const worst = Math.max(...acks.map(([, ack]) => ack.latency_ms));
      const rejected = acks.filter(([, ack]) => ack.event === "rejected").map(([thing]) => this.names[thing] || thing);
      how = rejected.length ? t("rejected by {robots}", { robots: rejected.join(", ") }) : t("acknowledged in {ms} ms", { ms: Math.round(worst) });
      if (command.target === "fleet") how += ` (${acks.length}/${command.robots.length})`;
    }
    return `${who}: ${t(command.action)}${zone} · ${how}`;
  }

  /** @param {TurnMessage} message */
  turn(message) {
    const item = node("li", "entry turn");
    item.append(node("span", "who", ORIGINS[message.origin ?? ""] || message.origin || t("Someone")), node("time", "", clock(message.at ?? Date.now())));
    const said = node("div", "said");
    said.appendChild(quoted(message.utterance || t("(session ended)")));
    item.appendChild(said);
    if (message.heard) {
      const sure = Math.round((message.heard.confidence ?? 0) * 100);
      item.appendChild(node("div", "heard", t("{seconds} s clip · the recognizer was {sure}% sure", { seconds: Number(message.heard.seconds ?? 0).toFixed(1), sure })));
    }
    const understood = node("div", "understood");
    if (message.intent) understood.appendChild(node("span", `tag intent${message.intent === FALLBACK ? " bad" : ""}`, message.intent));
    for (const [name, slot] of Object.entries(message.slots || {})) {
      if (!slot) continue;
      const resolved = slot.id ? ` → ${slot.id}` : slot.value ? ` (${t("no match")})` : "";
      understood.appendChild(node("span", "tag", `${name}: ${slot.value ?? "—"}${resolved}`));
    }
    if (understood.children.length) item.appendChild(understood);
    item.appendChild(node("div", `reply${message.intent === FALLBACK ? " sorry" : ""}`, message.speech || t("(no reply)")));
    const meta = node("div", "meta");
    item.appendChild(meta);
    const ids = message.commands || [];
    const redraw = () => {
      const parts = [t("reply in {ms} ms", { ms: Math.round(message.latency_ms ?? 0) })];
      parts.push(ids.length ? ids.map((id) => this.commandLine(id)).join(" · ") : t("no command"));
      meta.textContent = parts.join(" · ");
    };
    if (ids.length) for (const id of ids) this.watch(id, redraw);
    else redraw();
    return item;
  }

  /** @param {CommandMessage} message */
  command(message) {
    const robotSource = message.source.startsWith("robot:");
    const item = node("li", `entry ${robotSource ? "robot-exchange" : "console"}`);
    const who = robotSource ? t("{robot}, to a robot", { robot: this.names[message.source.slice(6)] || message.source.slice(6) }) : sourceName(message.source).replace(/^./, (c) => c.toUpperCase());
    item.append(node("span", "who", who), node("time", "", clock(message.seen ?? Date.now())));
    const said = node("div", "said");
    item.appendChild(said);
    this.watch(message.id, () => { said.textContent = this.commandLine(message.id); });
    return item;
  }

  // What the assistant said unprompted (the page shows it as an alert too).
  /** @param {AnnouncementMessage} message */
  announcement(message) {
    const item = node("li", "entry announcement");
    item.dataset.trouble = message.kind;
    item.append(node("span", "who", t("The assistant, unprompted")), node("time", "", clock(message.time)));
    item.appendChild(node("div", "reply", message.speech));
    return item;
  }

  /** @param {EventMessage} message */
  exchange(message) {
    const name = this.names[message.thing] || message.thing;
    const item = node("li", "entry robot-exchange");
    let who, body;
    if (message.event === "said") {
      who = t("{robot} to the assistant", { robot: name });
      body = quoted(message.text || "");
    } else if (message.event === "heard") {
      who = t("The assistant to {robot}", { robot: name });
      body = quoted(message.text || t("(nothing heard)"));
    } else {
      who = t("{robot} understood", { robot: name });
      const sure = message.confidence !== undefined && message.confidence !== null ? ` (${t("{sure}% sure", { sure: Math.round(message.confidence * 100) })})` : "";
      body = node("span", `tag ${message.intent && message.intent !== "unknown" ? "ok" : "bad"}`, `${message.intent || t("nothing")}${sure}`);
    }
    item.append(node("span", "who", who), node("time", "", clock(message.at ?? Date.now())));
    const said = node("div", "said");
    said.appendChild(body);
    item.appendChild(said);
    return item;
  }
}
