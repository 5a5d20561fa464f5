// @ts-check
// The fleet's task queue as the station lists it: the line first (queued tasks, oldest
// first, numbered), then the tasks robots are doing, then the latest finished or cancelled.

import { LOCALE, t as tr } from "./i18n.js";

/** @import { Task } from "./contract.js" */

// Finished and cancelled tasks listed below the queue.
export const ENDED_SHOWN = 5;

/**
 * A task as one line of the list.
 * @typedef {object} TaskLine
 * @property {string} id
 * @property {Task["status"]} status
 * @property {string} what "deliver to zone C", "navigate to zone D"
 * @property {string} who "first in line", "placebot one", "done by placebot two"
 */

/**
 * @param {Task[]} tasks as the dispatcher lists them
 * @param {(thing: string) => string} nameOf a robot's spoken name
 * @param {(zone: string) => string} zoneOf a zone as running text names it ("zone C")
 * @returns {TaskLine[]}
 */
export function taskLines(tasks, nameOf, zoneOf) {
  const byAge = (/** @type {Task} */ a, /** @type {Task} */ b) => (a.created_at || "").localeCompare(b.created_at || "");
  const queued = tasks.filter((t) => t.status === "queued").sort(byAge);
  const assigned = tasks.filter((t) => t.status === "assigned").sort(byAge);
  const ended = tasks.filter((t) => t.status === "done" || t.status === "cancelled").sort(byAge).slice(-ENDED_SHOWN).reverse();
  const what = (/** @type {Task} */ task) => (task.zone ? tr("{kind} to {zone}", { kind: tr(task.kind), zone: zoneOf(task.zone) }) : tr(task.kind));
  const someone = tr("a robot");
  return [
    ...queued.map((task, index) => ({ id: task.id, status: task.status, what: what(task), who: index === 0 ? tr("first in line") : tr("{place} in line", { place: ordinal(index + 1) }) })),
    ...assigned.map((task) => ({ id: task.id, status: task.status, what: what(task), who: task.thing ? nameOf(task.thing) : someone })),
    ...ended.map((task) => ({ id: task.id, status: task.status, what: what(task), who: task.status === "done" ? tr("done by {robot}", { robot: task.thing ? nameOf(task.thing) : someone }) : tr("cancelled") })),
  ];
}

/** "2nd", "3rd", "11th". @param {number} n */
export function ordinal(n) {
  if (LOCALE !== "en-US") return `${n}.`;
  const teen = n % 100 >= 11 && n % 100 <= 13;
  const suffix = teen ? "th" : ({ 1: "st", 2: "nd", 3: "rd" })[n % 10] || "th";
  return `${n}${suffix}`;
}
