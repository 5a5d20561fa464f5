// @ts-check
// The fleet's task queue as the station lists it: the line first (queued tasks, oldest
// first, numbered), then the tasks robots are doing, then the latest finished or cancelled.

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
  const what = (/** @type {Task} */ t) => (t.zone ? `${t.kind} to ${zoneOf(t.zone)}` : t.kind);
  return [
    ...queued.map((t, index) => ({ id: t.id, status: t.status, what: what(t), who: index === 0 ? "first in line" : `${ordinal(index + 1)} in line` })),
    ...assigned.map((t) => ({ id: t.id, status: t.status, what: what(t), who: t.thing ? nameOf(t.thing) : "a robot" })),
    ...ended.map((t) => ({ id: t.id, status: t.status, what: what(t), who: t.status === "done" ? `done by ${t.thing ? nameOf(t.thing) : "a robot"}` : "cancelled" })),
  ];
}

/** "2nd", "3rd", "11th". @param {number} n */
export function ordinal(n) {
  const teen = n % 100 >= 11 && n % 100 <= 13;
  const suffix = teen ? "th" : ({ 1: "st", 2: "nd", 3: "rd" })[n % 10] || "th";
  return `${n}${suffix}`;
}
