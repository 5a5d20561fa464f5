// @ts-check
// The alerts above the floor: what the assistant announced unprompted (a robot stuck, a task
// failed, a robot gone offline), each an element with role "alert" naming the robot and what
// happened, with a short beep when it arrives, until someone acknowledges it: its button
// (a click, or Enter or Space on it), or Enter anywhere on the page outside a control and the
// text box, which acknowledges the alert on top. The station hears of the acknowledgment and
// every page lets the alert go. alerts.js decides what is shown; this draws it.

import { post, reason, replyVoice } from "./api.js";
import { t } from "./i18n.js";
import { AlertQueue } from "./alerts.js";
import { clock, node } from "./dom.js";
import { typing } from "./talk.js";

/** @import { AnnouncementMessage } from "./contract.js" */
/** @import { Alert } from "./alerts.js" */
/** @import { Interactions } from "./interactions.js" */

const SHOWN = 2; // alerts drawn at once; the rest wait behind a count
/** What happened, in a word or two, per kind of announcement. @type {Record<AnnouncementMessage["kind"], string>} */
const TROUBLES = { stuck: t("stuck"), failed: t("task failed"), offline: t("offline"), waiting: t("task waiting"), cancelled: t("task cancelled"), done: t("task done"), battery_low: t("battery low") };
// A key pressed on one of these does what the element does, not the page's shortcut.
const CONTROLS = "button, a[href], input, select, textarea, summary, [contenteditable], [role=button]";

/**
 * The alerts' box and what the view tells the page.
 * @typedef {object} AlertsParts
 * @property {HTMLElement} box
 * @property {Interactions} interactions the acknowledgment is one of the participant's interactions
 * @property {Record<string, string>} names the robots' spoken names
 * @property {(troubled: Map<string, AnnouncementMessage["kind"]>) => void} onChange the robots with an open alert, and about what
 * @property {(problem: string) => void} onError
 * @property {() => void} [onBeep]
 */

export class AlertsView {
  /** @param {AlertsParts} parts */
  constructor({ box, interactions, names, onChange, onError, onBeep = () => {} }) {
    this.box = box;
    this.interactions = interactions;
    this.names = names;
    this.onChange = onChange;
    this.onError = onError;
    this.onBeep = onBeep;
    this.queue = new AlertQueue();
    /** @type {AudioContext | null} */
    this.audio = null;
    document.addEventListener("keydown", (event) => this.onKey(event));
  }

  // What the station says is open (a snapshot); beeps if it brought news (a reconnection).
  /** @param {AnnouncementMessage[]} alerts @param {boolean} quiet */
  reset(alerts, quiet) {
    const fresh = this.queue.reset(alerts);
    this.render();
    if (fresh && !quiet) this.beep();
  }

  // A new announcement; true when it shows (it was not seen before).
  /** @param {AnnouncementMessage} message */
  add(message) {
    if (!this.queue.add(message)) return false;
    this.render();
    this.beep();
    return true;
  }

  // The station says these were acknowledged (here or on another page).
  /** @param {string[]} ids */
  acknowledged(ids) {
    if (this.queue.acknowledged(ids)) this.render();
  }

  // The person acknowledged `alert`: it goes at once, and the station is told.
  /** @param {Alert} alert */
  acknowledge(alert) {
    const hadFocus = this.box.contains(document.activeElement);
    const ids = this.queue.acknowledge(alert.key);
    if (!ids.length) return;
    this.interactions.attach(Promise.resolve({ text: `acknowledge alert ${alert.key}` }));
    this.render();
    if (hadFocus) /** @type {HTMLElement | null} */ (this.box.querySelector(".alert-ack"))?.focus();
    post("/api/acknowledge", { id: ids[ids.length - 1] }).catch((err) => this.onError(`The alert was not acknowledged at the station: ${reason(err)}`));
  }

  /** @param {KeyboardEvent} event */
  onKey(event) {
    if (event.key !== "Enter" || event.repeat || event.ctrlKey || event.metaKey || event.altKey || event.shiftKey) return;
    if (typing(event.target) || (event.target instanceof Element && event.target.closest(CONTROLS))) return;
    const top = this.queue.list()[0];
    if (!top) return;
    event.preventDefault();
    this.acknowledge(top);
  }

  render() {
    const alerts = this.queue.list();
    this.box.replaceChildren(...alerts.slice(0, SHOWN).map((alert, index) => this.draw(alert, index === 0)));
    if (alerts.length > SHOWN) {
      const more = alerts.length - SHOWN;
      this.box.appendChild(node("p", "alerts-more", more === 1 ? t("1 more alert behind these: acknowledge one to see the next.") : t("{count} more alerts behind these: acknowledge one to see the next.", { count: more })));
    }
    this.box.hidden = alerts.length === 0;
    this.onChange(this.queue.troubled());
  }

  /** @param {Alert} alert @param {boolean} top */
  draw(alert, top) {
    const { latest } = alert;
    const name = latest.thing ? this.names[latest.thing] || latest.thing : t("The fleet");
    const item = node("div", "alert");
    item.setAttribute("role", "alert");
    item.dataset.trouble = latest.kind;
    item.dataset.key = alert.key;
    if (latest.thing) item.dataset.alertThing = latest.thing;
    item.appendChild(node("span", "alert-icon"));
    const words = node("div", "alert-words");
    const title = node("div", "alert-title");
    title.append(node("strong", "alert-robot", name), node("span", "alert-trouble", TROUBLES[latest.kind] || latest.kind));
    if (alert.count > 1) title.appendChild(node("span", "alert-count", t("{count} times", { count: alert.count })));
    title.appendChild(node("time", "", clock(latest.time)));
    words.append(title, node("div", "alert-speech", latest.speech));
    const ack = node("button", "btn btn-small alert-ack", t("Acknowledge"));
    ack.type = "button";
    ack.dataset.interaction = `acknowledge alert ${alert.key}`;
    ack.setAttribute("aria-label", `${t("Acknowledge")}: ${latest.speech}`);
    if (top) {
      ack.appendChild(node("kbd", "", "Enter"));
      ack.title = t("Acknowledge (Enter)");
    }
    ack.addEventListener("click", () => this.acknowledge(alert));
    item.append(words, ack);
    return item;
  }

  // A short two-tone beep, unless replies are muted or the browser will not play sound yet
  // (a page plays none before it was clicked or a key pressed on it); a burst beeps once.
  beep() {
    if (replyVoice() === "off" || !this.queue.beep()) return;
    if (!this.audio) {
      if (!navigator.userActivation?.hasBeenActive) return;
      this.audio = new AudioContext();
    }
    const audio = this.audio;
    if (audio.state === "suspended") audio.resume().catch(() => {});
    const start = audio.currentTime + 0.01;
    for (const [offset, pitch] of [[0, 880], [0.16, 660]]) {
      const tone = audio.createOscillator();
      const level = audio.createGain();
      tone.frequency.value = pitch;
      level.gain.setValueAtTime(0.0001, start + offset);
      level.gain.exponentialRampToValueAtTime(0.25, start + offset + 0.015);
      level.gain.exponentialRampToValueAtTime(0.0001, start + offset + 0.13);
      tone.connect(level).connect(audio.destination);
      tone.start(start + offset);
      tone.stop(start + offset + 0.14);
    }
    this.onBeep();
  }
}
