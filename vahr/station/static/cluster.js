// @ts-check
// Robots that crowd on the screen drawn as one mark: robots whose drawn positions fall in one
// square of the screen (`cell` pixels) make a cluster, shown at their mean position with
// their count and the colour of the most pressing status among them (a stuck robot in a
// crowd of idle ones still shows). A robot alone in its square is drawn as itself; the
// selected robot is always drawn as itself, on top.

/**
 * A robot where it is drawn, in screen pixels.
 * @typedef {object} Placed
 * @property {string} thing
 * @property {number} x
 * @property {number} y
 * @property {string} status
 */

/**
 * One mark on the map: a robot alone (`things.length === 1`) or a crowd.
 * @typedef {object} Cluster
 * @property {number} x mean position of its robots
 * @property {number} y
 * @property {string[]} things
 * @property {string} status the most pressing status among them
 */

// Most pressing first: what an operator must see even in a crowd.
export const URGENCY = ["error", "stuck", "offline", "stopped", "waiting", "loading", "unloading", "navigating", "idle"];

/** @param {string} status */
function rank(status) {
  const found = URGENCY.indexOf(status);
  return found < 0 ? URGENCY.length : found;
}

/**
 * Group `placed` robots by screen square; `keepApart` (the selected robot) is never merged.
 * Clusters come in the order their first robot was placed, so the drawing is stable.
 * @param {Placed[]} placed
 * @param {number} cell the square's side in pixels
 * @param {string | null} [keepApart]
 * @returns {Cluster[]}
 */
export function cluster(placed, cell, keepApart = null) {
  /** @type {Map<string, {sx: number, sy: number, things: string[], status: string}>} */
  const squares = new Map();
  /** @type {Cluster[]} */
  const apart = [];
  for (const robot of placed) {
    if (robot.thing === keepApart) {
      apart.push({ x: robot.x, y: robot.y, things: [robot.thing], status: robot.status });
      continue;
    }
    const key = `${Math.floor(robot.x / cell)},${Math.floor(robot.y / cell)}`;
    const square = squares.get(key);
    if (square === undefined) {
      squares.set(key, { sx: robot.x, sy: robot.y, things: [robot.thing], status: robot.status });
    } else {
      square.sx += robot.x;
      square.sy += robot.y;
      square.things.push(robot.thing);
      if (rank(robot.status) < rank(square.status)) square.status = robot.status;
    }
  }
  /** @type {Cluster[]} */
  const found = [];
  for (const { sx, sy, things, status } of squares.values()) {
    found.push({ x: sx / things.length, y: sy / things.length, things, status });
  }
  return found.concat(apart);
}

/**
 * The mark nearest to (x, y) within `reach` pixels, or null: what a click there means.
 * @param {Cluster[]} clusters
 * @param {number} x
 * @param {number} y
 * @param {number} reach
 * @returns {Cluster | null}
 */
export function hit(clusters, x, y, reach) {
  let best = null, bestDistance = reach * reach;
  for (const mark of clusters) {
    const d = (mark.x - x) ** 2 + (mark.y - y) ** 2;
    if (d <= bestDistance) {
      best = mark;
      bestDistance = d;
    }
  }
  return best;
}
