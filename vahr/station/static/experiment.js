// The experiment view and the participant's interactions.
//
// While `vahr experiment` runs a session, the page shows the participant's briefing (task I
// assignments, the task under way and its time; with the keyboard-and-mouse method the
// weather once the assistant has told it), the judge's live verdict per task, and a puzzle
// counter for the observer. Every click, key press and push-to-talk on the page is sent to
// the session's log as an interaction with its start and end: a click from the start of the
// pointer's movement towards it to the button's release, a key from press to release, a
// push-to-talk from the press to the end of the spoken reply. What an interaction caused
// (commands, the assistant's answer) goes with its end.

import { post } from "./api.js";

const STILL_MS = 400; // a pointer at rest this long starts a new movement when it moves
const REACH_MS = 4000; // a movement longer ago than this is not the reach for this click
const WEATHERS = ["sunny", "rainy"];
const METHODS = { vahr: "voice (VAHR)", keyboard: "keyboard and mouse" };
const ROMAN = ["I", "II", "III"];

const iso = (ms) => new Date(ms).toISOString();

export class Interactions {
  constructor() {
    this.session = null;
    this.count = 0;
    this.prefix = Math.random().toString(36).slice(2, 8);
    this.active = null;
    this.keys = new Map();
    this.pointer = null;
    this.lastMove = 0;
    this.moveStart = 0;
    document.addEventListener("pointermove", (event) => this.moved(event), { capture: true, passive: true });
    document.addEventListener("pointerdown", (event) => this.pointerDown(event), { capture: true });
    document.addEventListener("pointerup", (event) => this.pointerUp(event), { capture: true });
    document.addEventListener("pointercancel", (event) => this.pointerUp(event), { capture: true });
    document.addEventListener("keydown", (event) => this.keyDown(event), { capture: true });
    document.addEventListener("keyup", (event) => this.keyUp(event), { capture: true });
  }

  setSession(session) {
    this.session = session;
  }

  // -- one interaction ---------------------------------------------------------------

  start(channel, text, at) {
    this.count += 1;
    const interaction = { id: `${this.prefix}-${this.count}`, channel, text, at, commands: [], counts: false, asks: false, pending: [], session: this.session };
    this.active = interaction;
    this.send(interaction, "started", at);
    return interaction;
  }

  // What an action started during the current interaction will report when it settles.
  attach(promise, interaction = this.active) {
    if (!interaction) return;
    interaction.pending.push(promise.then((outcome) => {
      if (!outcome) return;
      if (outcome.commands?.length) { interaction.commands.push(...outcome.commands); interaction.counts = true; }
      if (outcome.asks) { interaction.asks = true; interaction.counts = true; }
      for (const field of ["speech", "intent", "error"]) if (outcome[field] !== undefined) interaction[field] = outcome[field];
    }));
  }

  async end(interaction, at) {
    if (!interaction || interaction.ended) return;
    interaction.ended = true;
    // A click's action starts after the release: give it a moment to attach itself.
    await new Promise((resolve) => setTimeout(resolve, 60));
    if (this.active === interaction) this.active = null;
    await Promise.allSettled(interaction.pending);
    this.send(interaction, "ended", at);
  }

  send(interaction, phase, at) {
    if (!interaction.session) return; // no session: nothing is logged anywhere
    const body = { id: interaction.id, phase, channel: interaction.channel, at: iso(at), text: String(interaction.text || "").slice(0, 200) };
    if (phase === "ended") {
      Object.assign(body, { commands: interaction.commands.slice(0, 16), counts: interaction.counts, asks: interaction.asks });
      for (const field of ["speech", "intent", "error"]) {
        if (interaction[field] !== undefined && interaction[field] !== null) body[field] = String(interaction[field]).slice(0, field === "speech" ? 1000 : 200);
      }
    }
    body.sent = iso(Date.now());
    post("/api/interaction", body).catch(() => {});
  }

  // -- clicks and keys, everywhere on the page --------------------------------------------

  moved(event) {
    const t = Date.now();
    if (t - this.lastMove > STILL_MS) this.moveStart = t;
    this.lastMove = t;
  }

  ignored(event) {
    return event.target instanceof Element && event.target.closest("[data-observer], #talk");
  }

  pointerDown(event) {
    if (!event.isPrimary || this.ignored(event)) return;
    const t = Date.now();
    const reach = event.pointerType === "mouse" && t - this.moveStart < REACH_MS ? this.moveStart : t;
    this.pointer = this.start("click", describe(event.target), Math.min(reach, t));
  }

  pointerUp(event) {
    if (!event.isPrimary || !this.pointer) return;
    const interaction = this.pointer;
    this.pointer = null;
    this.end(interaction, Date.now());
  }

  keyDown(event) {
    if (event.repeat || this.keys.has(event.code) || (event.code === "Space" && !typingIn(event.target))) return;
    this.keys.set(event.code, this.start("key", `key ${event.key}`, Date.now()));
  }

  keyUp(event) {
    const interaction = this.keys.get(event.code);
    if (!interaction) return;
    this.keys.delete(event.code);
    this.end(interaction, Date.now());
  }
}

function typingIn(target) {
  return target instanceof HTMLElement && ["INPUT", "TEXTAREA"].includes(target.tagName);
}

function describe(target) {
  if (!(target instanceof Element)) return "click";
  const thing = target.closest("[data-thing]")?.dataset.thing;
  const zone = target.closest("[data-zone]")?.dataset.zone;
  const labelled = target.closest("button, summary, select, input, [role=button]");
  const label = labelled?.getAttribute("aria-label") || labelled?.textContent?.trim();
  if (zone) return `click zone ${zone}`;
  if (thing) return `click robot ${thing}`;
  if (label) return `click ${label.replace(/\s+/g, " ").slice(0, 60)}`;
  return "click";
}

export class ExperimentView {
  // `now` is the station's time (the page's clock corrected by what the station said).
  constructor({ card, chip, briefing, verdicts, clock, puzzle, less, more, names, now }) {
    Object.assign(this, { card, chip, briefing, verdicts, clock, puzzle, names, now });
    this.status = null;
    this.weather = null;
    this.timer = null;
    less.addEventListener("click", () => this.puzzleStep(-1));
    more.addEventListener("click", () => this.puzzleStep(1));
  }

  // The session's status from `vahr experiment` (null when none runs).
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
    this.briefing.replaceChildren();
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
      const label = { waiting: "not yet", running: "running", success: "✓ success", failure: "✗ failure" }[verdict.state];
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

  puzzleStep(count) {
    if (!this.status) return;
    const now = new Date().toISOString();
    post("/api/puzzle", { count, at: now, sent: now }).catch(() => {});
  }
}
