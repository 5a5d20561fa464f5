// @ts-check
// A robot's change from the station (only what changed) applied to what the page knows of
// it: the reported fields merged in, the removed ones dropped, the rest replaced.

/** @import { RobotChange, RobotView } from "./contract.js" */

/**
 * Apply `change` to `robot` in place.
 * @param {RobotView} robot
 * @param {RobotChange} change
 */
export function applyChange(robot, change) {
  if (change.reported || change.removed) {
    /** @type {Record<string, unknown>} */
    const reported = { ...(robot.reported || {}), ...(change.reported || {}) };
    for (const key of change.removed || []) delete reported[key];
    robot.reported = reported;
  }
  if (change.version !== undefined) robot.version = change.version;
  if (change.online !== undefined) robot.online = change.online;
  if (change.last_seen !== undefined) robot.last_seen = change.last_seen;
  // The latest event first: `progress` is the drive's state after both.
  if (change.last_event !== undefined) robot.last_event = change.last_event;
  if (change.progress !== undefined) robot.progress = change.progress;
}
