// @ts-check
// The audit trail card: the latest records of who did what, through which channel, and what
// came of it (the trail itself: `vahr audit`). Newest first.

import { clock, node } from "./dom.js";
import { t } from "./i18n.js";

/** @import { AuditRecord, TrailMessage } from "./contract.js" */

// The words this view shows, in the page's language.
const WORDS = {
  empty: () => t("Nothing recorded yet."),
  /** @param {number} count */
  count: (count) => t("latest {count}", { count }),
  /** @param {string} channel */
  channel: (channel) => (CHANNELS[channel] ? CHANNELS[channel]() : channel),
  /** @param {string} outcome */
  outcome: (outcome) => (OUTCOMES[outcome] ? OUTCOMES[outcome]() : outcome),
};
/** @type {Record<string, () => string>} */
const CHANNELS = {
  alexa: () => "Alexa",
  "station-voice": () => t("push-to-talk"),
  station: () => t("typed"),
  "station-weather": () => t("weather button"),
  "station-panel": () => t("panel"),
  api: () => t("tasks API"),
  dispatcher: () => t("dispatcher"),
  announcer: () => t("announcer"),
  robot: () => t("a robot"),
};
/** @type {Record<string, () => string>} */
const OUTCOMES = {
  sent: () => t("sent"),
  confirmed: () => t("confirmed"),
  refused: () => t("refused"),
  asked: () => t("asked"),
  cancelled: () => t("cancelled"),
  failed: () => t("failed"),
  answered: () => t("answered"),
  unsent: () => t("unsent"),
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
      if (record.role) who.append(node("small", "trail-role", ` ${t(record.role)}`));
      const robots = record.robots.length ? ` → ${record.robots.map(this.nameOf).join(", ")}` : "";
      item.append(
        node("span", "trail-time", clock(record.time)),
        who,
        node("span", "trail-channel", WORDS.channel(record.channel)),
        node("span", "trail-outcome", WORDS.outcome(record.outcome)),
        node("span", "trail-what", `${recordWhat(record)}${robots}`),
      );
      if (record.reason) item.title = record.reason;
      return item;
    });
    if (!items.length) items.push(node("li", "trail-empty", WORDS.empty()));
    this.list.replaceChildren(...items);
    this.count.textContent = WORDS.count(message.records.length);
  }
}
