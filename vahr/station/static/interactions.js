// @ts-check
// The participant's interactions, measured: each click, key press and push-to-talk with its
// start and end, sent to the session's log when it starts and when it ends.
//
// A click lasts from the start of the pointer's movement towards it (a pointer at rest for
// STILL_MS starts a new movement) to the button's release; on a touch screen, from touch to
// release. A key lasts from press to release; a push-to-talk from the press to the end of
// the spoken reply (talk.js ends it). What an interaction caused (the commands it sent, the
// assistant's answer) goes with its end. Pure: the page's listeners (experiment.js) hand it
// plain facts, and the node tests (tests/js/) run it on a clock of their own.

/** @import { Interaction as InteractionMessage } from "./contract.js" */

export const STILL_MS = 400; // a pointer at rest this long starts a new movement when it moves
export const REACH_MS = 4000; // a movement longer ago than this is not the reach for this click
export const SETTLE_MS = 60; // a click's action starts after the release: time to attach itself

/** @typedef {InteractionMessage["channel"]} Channel */

/**
 * What an action started during an interaction reports when it settles.
 * @typedef {object} Outcome
 * @property {string[]} [commands]
 * @property {boolean} [asks]
 * @property {string | null} [speech]
 * @property {string | null} [intent]
 * @property {string | null} [error]
 * @property {string} [text] what the interaction did, in words, when the element it began on
 *   does not say it (a key that acknowledged an alert): its text from then on
 */

/**
 * One interaction under way (talk.js fills in what a push-to-talk came to).
 * @typedef {object} Interaction
 * @property {string} id
 * @property {Channel} channel
 * @property {string} text
 * @property {number} at when it started (ms since the epoch, the page's clock)
 * @property {string[]} commands
 * @property {boolean} counts
 * @property {boolean} asks
 * @property {Promise<void>[]} pending
 * @property {string | null} session
 * @property {boolean} [ended]
 * @property {string | null} [speech]
 * @property {string | null} [intent]
 * @property {string | null} [error]
 */

/** What the page posts to the session's log (the station adds the session and the kind). @typedef {Omit<InteractionMessage, "kind" | "session">} InteractionBody */

const iso = (/** @type {number} */ ms) => new Date(ms).toISOString();

export class Interactions {
  /**
   * @param {object} options
   * @param {(body: InteractionBody) => void} options.send where a start or an end goes
   * @param {() => number} [options.now] the page's clock, ms since the epoch
   * @param {(ms: number) => Promise<unknown>} [options.wait]
   * @param {string} [options.prefix] what this page's interaction ids start with
   */
  constructor({ send, now = Date.now, wait = (ms) => new Promise((resolve) => setTimeout(resolve, ms)), prefix = Math.random().toString(36).slice(2, 8) }) {
    this.post = send;
    this.now = now;
    this.wait = wait;
    this.prefix = prefix;
    /** @type {string | null} */
    this.session = null;
    this.count = 0;
    /** The interaction an action started now belongs to. @type {Interaction | null} */
    this.active = null;
    /** @type {Map<string, Interaction>} */
    this.keys = new Map();
    /** @type {Interaction | null} */
    this.pointer = null;
    this.lastMove = 0;
    this.moveStart = 0;
  }

  /** @param {string | null} session */
  setSession(session) {
    this.session = session;
  }

  // -- one interaction ---------------------------------------------------------------

  /** @param {Channel} channel @param {string} text @param {number} at */
  start(channel, text, at) {
    this.count += 1;
    /** @type {Interaction} */
    const interaction = { id: `${this.prefix}-${this.count}`, channel, text, at, commands: [], counts: false, asks: false, pending: [], session: this.session };
    this.active = interaction;
    this.send(interaction, "started", at);
    return interaction;
  }

  // What an action started during the current interaction will report when it settles.
  /** @param {Promise<Outcome | null | undefined>} promise @param {Interaction | null} [interaction] */
  attach(promise, interaction = this.active) {
    if (!interaction) return;
    interaction.pending.push(promise.then((outcome) => {
      if (!outcome) return;
      if (outcome.commands?.length) { interaction.commands.push(...outcome.commands); interaction.counts = true; }
      if (outcome.asks) { interaction.asks = true; interaction.counts = true; }
      for (const field of /** @type {const} */ (["speech", "intent", "error"])) if (outcome[field] !== undefined) interaction[field] = outcome[field];
      if (outcome.text) interaction.text = outcome.text;
    }));
  }

  /** @param {Interaction | null | undefined} interaction @param {number} at */
  async end(interaction, at) {
    if (!interaction || interaction.ended) return;
    interaction.ended = true;
    // A click's action starts after the release: give it a moment to attach itself.
    await this.wait(SETTLE_MS);
    if (this.active === interaction) this.active = null;
    await Promise.allSettled(interaction.pending);
    this.send(interaction, "ended", at);
  }

  /** @param {Interaction} interaction @param {"started" | "ended"} phase @param {number} at */
  send(interaction, phase, at) {
    if (!interaction.session) return; // no session: nothing is logged anywhere
    const body = { id: interaction.id, phase, channel: interaction.channel, at: iso(at), text: String(interaction.text || "").slice(0, 200) };
    /** @type {Partial<InteractionBody>} */
    const outcome = {};
    if (phase === "ended") {
      Object.assign(outcome, { commands: interaction.commands.slice(0, 16), counts: interaction.counts, asks: interaction.asks });
      for (const field of /** @type {const} */ (["speech", "intent", "error"])) {
        const value = interaction[field];
        if (value !== undefined && value !== null) outcome[field] = String(value).slice(0, field === "speech" ? 1000 : 200);
      }
    }
    this.post({ ...body, ...outcome, sent: iso(this.now()) });
  }

  // -- clicks and keys, from the page's listeners --------------------------------------------

  // The pointer moved.
  moved(t = this.now()) {
    if (t - this.lastMove > STILL_MS) this.moveStart = t;
    this.lastMove = t;
  }

  // The primary pointer went down on `text` ("click zone B"); a mouse's click started with
  // the movement towards it, a touch when it touched.
  /** @param {{mouse: boolean, text: string}} press @param {number} [t] */
  pointerDown({ mouse, text }, t = this.now()) {
    const reach = mouse && t - this.moveStart < REACH_MS ? this.moveStart : t;
    this.pointer = this.start("click", text, Math.min(reach, t));
  }

  // The primary pointer went up (or was cancelled).
  pointerUp(t = this.now()) {
    if (!this.pointer) return;
    const interaction = this.pointer;
    this.pointer = null;
    this.end(interaction, t);
  }

  // A key went down (not a repeat); a key already down is one interaction until it is up.
  /** @param {string} code @param {string} key @param {number} [t] */
  keyDown(code, key, t = this.now()) {
    if (this.keys.has(code)) return;
    this.keys.set(code, this.start("key", `key ${key}`, t));
  }

  /** @param {string} code @param {number} [t] */
  keyUp(code, t = this.now()) {
    const interaction = this.keys.get(code);
    if (!interaction) return;
    this.keys.delete(code);
    this.end(interaction, t);
  }
}
