// @ts-check
// The experiment view and the participant's interactions.
//
// While `vahr experiment` runs a session, the page shows the participant's briefing (task I
// assignments, the task under way and its time; with the keyboard-and-mouse method the
// weather once the assistant has told it), the judge's live verdict per task, and a puzzle
// counter for the observer. Every click, key press and push-to-talk on the page is sent to
// the session's log as an interaction with its start and end (interactions.js measures
// them; `watchInteractions` hands it the page's clicks and keys).

import { post } from "./api.js";

/** @import { ExperimentStatus } from "./contract.js" */
/** @import { Interactions } from "./interactions.js" */

const WEATHERS = ["sunny", "rainy"];
/** @type {Record<string, string>} */
const METHODS = { vahr: "voice (VAHR)", keyboard: "keyboard and mouse" };
const ROMAN = ["I", "II", "III"];
/** @type {Record<string, string>} */
const VERDICTS = { waiting: "not yet", running: "running", success: "✓ success", failure: "✗ failure" };

// Every click and key press anywhere on the page, handed to `interactions` as plain facts
// (the observer's controls and push-to-talk, which measures itself, are left out).
/** @param {Interactions} interactions @param {Document} [page] */
export function watchInteractions(interactions, page = document) {
  page.addEventListener("pointermove", () => interactions.moved(), { capture: true, passive: true });
  page.addEventListener("pointerdown", (event) => {
    if (!event.isPrimary || ignored(event.target)) return;
    interactions.pointerDown({ mouse: event.pointerType === "mouse", text: describe(event.target) });
  }, { capture: true });
  /** @param {PointerEvent} event */
  const up = (event) => { if (event.isPrimary) interactions.pointerUp(); };
  page.addEventListener("pointerup", up, { capture: true });
  page.addEventListener("pointercancel", up, { capture: true });
  page.addEventListener("keydown", (event) => {
    if (event.repeat || (event.code === "Space" && !typingIn(event.target))) return;
    interactions.keyDown(event.code, event.key);
  }, { capture: true });
  page.addEventListener("keyup", (event) => interactions.keyUp(event.code), { capture: true });
}

/** @param {EventTarget | null} target */
function ignored(target) {
  return target instanceof Element && target.closest("[data-observer], #talk") !== null;
}

/** @param {EventTarget | null} target */
function typingIn(target) {
  return target instanceof HTMLElement && ["INPUT", "TEXTAREA"].includes(target.tagName);
}

/** @param {EventTarget | null} target */
function describe(target) {
  if (!(target instanceof Element)) return "click";
  // An element that says what a click on it does (an alert's Acknowledge) is named so.
  const does = target.closest("[data-interaction]")?.getAttribute("data-interaction");
  if (does) return does;
  const thing = target.closest("[data-thing]")?.getAttribute("data-thing");
  const zone = target.closest("[data-zone]")?.getAttribute("data-zone");
  const labelled = target.closest("button, summary, select, input, [role=button]");
  const label = labelled?.getAttribute("aria-label") || labelled?.textContent?.trim();
  if (zone) return `click zone ${zone}`;
  if (thing) return `click robot ${thing}`;
  if (label) return `click ${label.replace(/\s+/g, " ").slice(0, 60)}`;
  return "click";
}

/**
 * The experiment card's elements, the robots' spoken names, and the station's time (the
 * page's clock corrected by what the station said).
 * @typedef {object} ExperimentParts
 * @property {HTMLElement} card
 * @property {HTMLElement} chip
 * @property {HTMLElement} briefing
 * @property {HTMLElement} verdicts
 * @property {HTMLElement} clock
 * @property {HTMLOutputElement} puzzle
 * @property {HTMLElement} less
 * @property {HTMLElement} more
 * @property {Record<string, string>} names
 * @property {() => number} now
 */

export class ExperimentView {
  /** @param {ExperimentParts} parts */
  constructor({ card, chip, briefing, verdicts, clock, puzzle, less, more, names, now }) {
    this.card = card;
    this.chip = chip;
    this.briefing = briefing;
    this.verdicts = verdicts;
    this.clock = clock;
    this.puzzle = puzzle;
    this.names = names;
    this.now = now;
    /** @type {ExperimentStatus | null} */
    this.status = null;
    /** @type {string | null} */
    this.weather = null;
    /** @type {number | undefined} */
    this.timer = undefined;
    less.addEventListener("click", () => this.puzzleStep(-1));
    more.addEventListener("click", () => this.puzzleStep(1));
  }

  // The session's status from `vahr experiment` (null when none runs).
  /** @param {ExperimentStatus | null} status */
  update(status) {
    const previous = this.status;
    this.status = status && !status.ended ? status : null;
    if (!previous || !this.status || previous.session !== this.status.session) this.weather = null;
    this.card.hidden = !this.status;
    this.chip.hidden = !this.status;
    clearInterval(this.timer);
    if (!this.status) return;
    const s = this.status;
    this.chip.textContent = `Session ${s.session}${s.simulated ? " (simulated)" : ""}`;
    this.puzzle.value = String(s.puzzle ?? 0);
    this.puzzle.textContent = String(s.puzzle ?? 0);
    this.render();
    this.tickClock();
    this.timer = setInterval(() => this.tickClock(), 1000);
  }

  // A reply of the assistant: with the keyboard-and-mouse method the participant learns the
  // weather by asking, so the briefing shows it once it has been said.
  /** @param {string | null | undefined} speech */
  heard(speech) {
    if (!this.status || this.status.method !== "keyboard" || !speech) return;
    const words = new Set(speech.toLowerCase().match(/[a-z]+/g) || []);
    const named = WEATHERS.filter((w) => words.has(w));
    if (named.length === 1) {
      this.weather = named[0];
      this.render();
    }
  }

  render() {
    const s = this.status;
    if (!s) return;
    this.briefing.replaceChildren();
    /** @param {string} className @param {string} text */
    const line = (className, text) => {
      const div = document.createElement("div");
      div.className = className;
      div.textContent = text;
      this.briefing.appendChild(div);
      return div;
    };
    line("muted", `${s.participant} · ${METHODS[s.method] || s.method} · trial ${s.trial}`);
    const current = s.task ? s.tasks?.[s.task] : null;
    line("task-now", s.task ? `Now: task ${s.task}, ${current?.title ?? ""}` : "Between tasks");
    const assigned = Object.entries(s.assignments || {}).map(([thing, zone]) => `${this.names[thing] || thing} → ${zone}`);
    if (assigned.length) line("", `Task I zones: ${assigned.join(", ")}`);
    if (s.method === "keyboard") {
      line(this.weather ? "" : "muted", this.weather ? `Weather: ${this.weather} (as the assistant said)` : "Weather: ask the assistant");
    }
    this.verdicts.replaceChildren();
    for (const task of ROMAN) {
      const verdict = s.tasks?.[task] || { state: "waiting" };
      const item = document.createElement("li");
      item.className = verdict.state;
      item.dataset.task = task;
      const label = VERDICTS[verdict.state];
      for (const [className, text] of [["task", `Task ${task}`], ["state", label], ["why", verdict.reason || ""]]) {
        const span = document.createElement("span");
        span.className = className;
        span.textContent = text;
        if (className === "why") span.title = text;
        item.appendChild(span);
      }
      this.verdicts.appendChild(item);
    }
  }

  tickClock() {
    const s = this.status;
    const started = s?.task ? s.tasks?.[s.task]?.started_at : s?.started_at;
    if (!started) {
      this.clock.textContent = "--:--";
      return;
    }
    const seconds = Math.max(0, Math.floor((this.now() - Date.parse(started)) / 1000));
    this.clock.textContent = `${String(Math.floor(seconds / 60)).padStart(2, "0")}:${String(seconds % 60).padStart(2, "0")}`;
  }

  /** @param {number} count */
  puzzleStep(count) {
    if (!this.status) return;
    const now = new Date().toISOString();
    post("/api/puzzle", { count, at: now, sent: now }).catch(() => {});
  }
}
