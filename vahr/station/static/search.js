// @ts-check
// Finding robots in a large fleet: by spoken name or thing name, narrowed by status and zone.
// A name that matches whole comes first, then names that start with the words typed, then
// the rest that contain them; within each, the fleet's order.

/**
 * What a robot is found by.
 * @typedef {object} Findable
 * @property {string} thing
 * @property {string} name its spoken name
 * @property {string} status "offline", or the reported status
 * @property {string | null} zone the reported zone
 */

/**
 * @typedef {object} Query
 * @property {string} text what was typed
 * @property {string} [status] only robots with this status ("" or absent: any)
 * @property {string} [zone] only robots in this zone ("" or absent: any)
 */

/** Lower case, single spaces. @param {string} text */
export function normalise(text) {
  return text.toLowerCase().replace(/\s+/g, " ").trim();
}

/** Without spaces, dashes, dots or underscores: "placebot 1" finds "placebot1". @param {string} text */
const compact = (text) => normalise(text).replace(/[\s_.-]+/g, "");

/**
 * The robots that match `query`, best first.
 * @param {Findable[]} robots in the fleet's order
 * @param {Query} query
 * @returns {string[]} their things
 */
export function findRobots(robots, query) {
  const text = normalise(query.text);
  const tight = compact(query.text);
  /** @type {string[][]} */
  const ranks = [[], [], []];
  for (const robot of robots) {
    if (query.status && robot.status !== query.status) continue;
    if (query.zone && robot.zone !== query.zone) continue;
    if (!text) {
      ranks[2].push(robot.thing);
      continue;
    }
    const name = normalise(robot.name), thing = normalise(robot.thing);
    if (name === text || thing === text) ranks[0].push(robot.thing);
    else if (name.startsWith(text) || thing.startsWith(text) || compact(robot.thing).startsWith(tight)) ranks[1].push(robot.thing);
    else if (name.includes(text) || thing.includes(text) || compact(robot.name).includes(tight) || compact(robot.thing).includes(tight)) ranks[2].push(robot.thing);
  }
  return ranks.flat();
}
