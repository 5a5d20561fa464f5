// @ts-check
// The alerts a page shows: what the assistant announced unprompted, until acknowledged.
//
// One alert per robot and trouble: a second announcement of the same kind about the same
// robot while the first is still open (the fault cleared and came back) joins it, counted,
// with the newer words. An announcement seen before (delivered twice, or in a new snapshot)
// is not shown again, and one acknowledged here stays acknowledged whatever a snapshot
// taken before the station heard of it says. Most urgent first (the announcement's
// priority), then the oldest. Pure: the page (alerts-view.js) draws what this decides, and
// the node tests (tests/js/) run it on a clock of their own.

/** @import { AnnouncementMessage } from "./contract.js" */

export const BEEP_GAP_MS = 2000; // alerts arriving closer together than this share one beep
export const REMEMBERED = 1000; // announcement ids remembered as seen or acknowledged
export const IDS_PER_ALERT = 100; // as many as the station keeps open (its ALERTS_LIMIT)

/**
 * One alert on the page: the announcements it stands for (oldest first, the latest
 * IDS_PER_ALERT), the newest of them, and how many there were.
 * @typedef {object} Alert
 * @property {string} key the robot and the trouble ("placebot1 stuck"), or the announcement's id without a robot
 * @property {AnnouncementMessage} latest
 * @property {string[]} ids
 * @property {number} count how many announcements it stands for
 * @property {number} first when the first of them was announced (ms since the epoch)
 */

/** @param {AnnouncementMessage} message */
export function alertKey(message) {
  return message.thing ? `${message.thing} ${message.kind}` : message.id;
}

export class AlertQueue {
  /** @param {{now?: () => number}} [options] the page's clock, ms since the epoch */
  constructor({ now = Date.now } = {}) {
    this.now = now;
    /** @type {Map<string, Alert>} */
    this.open = new Map();
    /** Ids shown at some point. @type {Set<string>} */
    this.seen = new Set();
    /** Ids acknowledged on this page or by the station. @type {Set<string>} */
    this.acknowledgedIds = new Set();
    this.lastBeep = -Infinity;
  }

  // An announcement from the station; the alert it shows in, or null if it was seen before.
  /** @param {AnnouncementMessage} message @returns {Alert | null} */
  add(message) {
    if (this.seen.has(message.id) || this.acknowledgedIds.has(message.id)) return null;
    remember(this.seen, message.id);
    const key = alertKey(message);
    const alert = this.open.get(key);
    if (alert) {
      alert.ids.push(message.id);
      if (alert.ids.length > IDS_PER_ALERT) alert.ids.shift();
      alert.count += 1;
      alert.latest = message;
      return alert;
    }
    const made = { key, latest: message, ids: [message.id], count: 1, first: Date.parse(message.time) };
    this.open.set(key, made);
    return made;
  }

  // What the station says is open now (a snapshot): alerts acknowledged elsewhere in the
  // meantime go; returns how many announcements it brought that were not seen before.
  /** @param {AnnouncementMessage[]} messages */
  reset(messages) {
    const open = new Set(messages.map((m) => m.id));
    for (const alert of [...this.open.values()]) {
      alert.ids = alert.ids.filter((id) => open.has(id));
      if (!alert.ids.length) this.open.delete(alert.key);
    }
    let fresh = 0;
    for (const message of messages) if (this.add(message)) fresh += 1;
    return fresh;
  }

  // The person acknowledged the alert `key`; the announcement ids it stood for.
  /** @param {string} key @returns {string[]} */
  acknowledge(key) {
    const alert = this.open.get(key);
    if (!alert) return [];
    this.open.delete(key);
    for (const id of alert.ids) remember(this.acknowledgedIds, id);
    return alert.ids;
  }

  // The station says these announcements were acknowledged (on this page or another);
  // true if an alert shown here changed.
  /** @param {string[]} ids */
  acknowledged(ids) {
    let changed = false;
    for (const id of ids) remember(this.acknowledgedIds, id);
    for (const alert of [...this.open.values()]) {
      const left = alert.ids.filter((id) => !this.acknowledgedIds.has(id));
      if (left.length === alert.ids.length) continue;
      changed = true;
      alert.ids = left;
      if (!left.length) this.open.delete(alert.key);
    }
    return changed;
  }

  // The open alerts, most urgent first, then the oldest.
  /** @returns {Alert[]} */
  list() {
    return [...this.open.values()].sort((a, b) => b.latest.priority - a.latest.priority || a.first - b.first);
  }

  // Per robot, the most urgent trouble it has an open alert for (the map highlights it).
  /** @returns {Map<string, AnnouncementMessage["kind"]>} */
  troubled() {
    /** @type {Map<string, AnnouncementMessage["kind"]>} */
    const found = new Map();
    for (const alert of this.list()) {
      const thing = alert.latest.thing;
      if (thing && !found.has(thing)) found.set(thing, alert.latest.kind);
    }
    return found;
  }

  // Whether a new alert should beep now: a burst of them beeps once.
  beep(t = this.now()) {
    if (t - this.lastBeep < BEEP_GAP_MS) return false;
    this.lastBeep = t;
    return true;
  }
}

/** Add `id` to `ids`, forgetting the oldest past REMEMBERED. @param {Set<string>} ids @param {string} id */
function remember(ids, id) {
  ids.add(id);
  if (ids.size > REMEMBERED) ids.delete(/** @type {string} */ (ids.values().next().value));
}
