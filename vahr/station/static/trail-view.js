// @ts-check
// The audit trail card: the latest records of who did what, through which channel, and what
// came of it (the trail itself: `vahr audit`). Newest first.

import { clock, node } from "./dom.js";

/** @import { AuditRecord, TrailMessage } from "./contract.js" */

// The words this view shows (one place, for translation).
const WORDS = {
  empty: "Nothing recorded yet.",
  /** @param {number} count */
  count: (count) => `latest ${count}`,
  channels: /** @type {Record<string, string>} */ ({
    alexa: "Alexa",
    "station-voice": "push-to-talk",
    station: "typed",
    "station-weather": "weather button",
    "station-panel": "panel",
    api: "tasks API",
    dispatcher: "dispatcher",
    announcer: "announcer",
    robot: "a robot",
  }),
};

/** What the record asked for, in a few words. @param {AuditRecord} record */
export function recordWhat(record) {
  if (record.words) return `“${record.words}”`;
  const slots = Object.values(record.slots || {}).filter(Boolean).join(", ");
  return `${record.intent || "?"}${slots ? ` (${slots})` : ""}`;
}

export class TrailView {
  /** @param {{card: HTMLElement, list: HTMLElement, count: HTMLElement}} parts @param {(thing: string) => string} nameOf */
  constructor({ card, list, count }, nameOf) {
    this.card = card;
    this.list = list;
    this.count = count;
    this.nameOf = nameOf;
  }

  /** @param {TrailMessage | null | undefined} message */
  update(message) {
    this.card.hidden = !message;
    if (!message) return;
    const items = [...message.records].reverse().map((record) => {
      const item = node("li", "trail-line");
      item.dataset.outcome = record.outcome;
      item.dataset.seq = String(record.seq);
      const who = node("span", "trail-who", record.name || record.who);
      if (record.role) who.append(node("small", "trail-role", ` ${record.role}`));
      const robots = record.robots.length ? ` → ${record.robots.map(this.nameOf).join(", ")}` : "";
      item.append(
        node("span", "trail-time", clock(record.time)),
        who,
        node("span", "trail-channel", WORDS.channels[record.channel] || record.channel),
        node("span", "trail-outcome", record.outcome),
        node("span", "trail-what", `${recordWhat(record)}${robots}`),
      );
      if (record.reason) item.title = record.reason;
      return item;
    });
    if (!items.length) items.push(node("li", "trail-empty", WORDS.empty));
    this.list.replaceChildren(...items);
    this.count.textContent = WORDS.count(message.records.length);
  }
}
