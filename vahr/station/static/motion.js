// @ts-check
// Where one robot is drawn: reported poses in, a position and heading at any moment out.
//
// Robots report their pose now and then (every second on the local stack, far less often
// on AWS), so between reports a robot moves along its path: a straight line from the last
// reported pose toward the destination, at the speed its reports imply (or that of its
// previous drive). A report that disagrees is eased into over a moment, never jumped to,
// and a robot is never drawn sliding backwards along its path. Pure: the map draws it, and
// the node tests (tests/js/) run it on a clock of their own.

export const DEFAULT_SPEED = 0.5; // metres a second: the simulator's, until reports say otherwise
export const EASE_MS = 600;
export const TURN_RATE = 5; // radians a second at which the drawn heading follows

/** @typedef {{x: number, y: number}} Point */
/** A reported pose (theta may be missing). @typedef {{x: number, y: number, theta?: number | null}} ReportedPose */

/** @param {Point} a @param {Point} b */
export const distance = (a, b) => Math.hypot(a.x - b.x, a.y - b.y);
/** @param {number} t */
const smooth = (t) => 1 - Math.pow(1 - Math.min(Math.max(t, 0), 1), 3);
/** The signed smallest turn from heading a to heading b. @param {number} a @param {number} b */
export const angleDelta = (a, b) => Math.atan2(Math.sin(b - a), Math.cos(b - a));

export class Motion {
  /**
   * @param {ReportedPose} pose where the robot starts
   * @param {() => number} [now] the clock, in milliseconds (the page's `performance.now`)
   */
  constructor(pose, now = () => performance.now()) {
    this.now = now;
    /** @type {Point & {t: number}} */
    this.anchor = { x: pose.x, y: pose.y, t: now() };
    this.theta = pose.theta ?? 0;
    this.heading = this.theta;
    /** @type {Point | null} */
    this.target = null;
    this.speed = DEFAULT_SPEED;
    this.offset = { x: 0, y: 0, t: 0 };
    /** The last report while driving: its pose, time and target. @type {{pose: Point, t: number, target: Point} | null} */
    this.last = null;
  }

  /** Where the robot is drawn at time `t`. @param {number} t @returns {Point} */
  position(t) {
    let { x, y } = this.anchor;
    if (this.target) {
      const remaining = distance(this.anchor, this.target);
      const travelled = Math.min(remaining, (this.speed * (t - this.anchor.t)) / 1000);
      if (remaining > 1e-6) {
        x += ((this.target.x - x) * travelled) / remaining;
        y += ((this.target.y - y) * travelled) / remaining;
      }
    }
    const fade = 1 - smooth((t - this.offset.t) / EASE_MS);
    return { x: x + this.offset.x * fade, y: y + this.offset.y * fade };
  }

  /** True while a report that disagreed is still being eased into. */
  get settling() {
    return this.now() - this.offset.t < EASE_MS;
  }

  /** True while the robot is drawn short of its target. */
  get driving() {
    return this.target !== null && distance(this.position(this.now()), this.target) > 0.01;
  }

  /**
   * A reported `pose`; `target` is the destination's pose while driving, else null.
   * @param {ReportedPose} pose
   * @param {Point | null} target
   */
  report(pose, target) {
    const t = this.now();
    const shown = this.position(t);
    if (target && this.last && this.last.target && distance(this.last.target, target) < 1e-6) {
      const seconds = (t - this.last.t) / 1000;
      const covered = distance(this.last.pose, pose);
      if (seconds > 0.05 && covered > 0.01) {
        // The speed the reports imply, blended with what was believed before.
        this.speed = 0.5 * this.speed + 0.5 * Math.min(Math.max(covered / seconds, 0.02), 100);
      }
    }
    let anchor = { x: pose.x, y: pose.y, t };
    if (target && distance(shown, target) < distance(pose, target)) {
      // The robot is behind where it was drawn: hold the drawn place rather than back up;
      // the speed just measured lets the report catch up.
      anchor = { x: shown.x, y: shown.y, t };
    }
    this.offset = { x: shown.x - anchor.x, y: shown.y - anchor.y, t };
    this.anchor = anchor;
    this.target = target;
    if (pose.theta !== undefined && pose.theta !== null) this.theta = pose.theta;
    this.last = target ? { pose: { x: pose.x, y: pose.y }, t, target } : null;
  }

  /**
   * The heading drawn at time `t`, `dt` seconds after the last: it turns toward the way the
   * robot drives (or its reported heading once there) at most TURN_RATE a second.
   * @param {number} t
   * @param {number} dt
   */
  headingAt(t, dt) {
    let wanted = this.theta;
    if (this.target) {
      const at = this.position(t);
      if (distance(at, this.target) > 0.05) wanted = Math.atan2(this.target.y - at.y, this.target.x - at.x);
    }
    const step = TURN_RATE * dt;
    const delta = angleDelta(this.heading, wanted);
    this.heading += Math.abs(delta) <= step ? delta : Math.sign(delta) * step;
    return this.heading;
  }
}
