// @ts-check
// Where one robot is drawn: reported poses in, a position and heading at any moment out.
//
// Robots report their pose now and then (every second on the local stack, far less often
// on AWS), so between reports a robot moves along its path: the path it planned on the map
// when it reported one (its shadow's `path`), else a straight line, from the last reported
// pose toward the destination, at the speed its reports imply (or that of its previous
// drive). A report that disagrees is eased into over a moment, never jumped to,
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
    /** The planned path's points still ahead of the anchor, the target last. @type {Point[]} */
    this.ahead = [];
  }

  /** Where the robot is drawn at time `t`. @param {number} t @returns {Point} */
  position(t) {
    let at = { x: this.anchor.x, y: this.anchor.y };
    if (this.target) at = walk(at, this.ahead, (this.speed * (t - this.anchor.t)) / 1000);
    const fade = 1 - smooth((t - this.offset.t) / EASE_MS);
    return { x: at.x + this.offset.x * fade, y: at.y + this.offset.y * fade };
  }

  /** The points the robot is drawn still to pass at time `t`, the target last. @param {number} t @returns {Point[]} */
  remaining(t) {
    if (!this.target) return [];
    return ahead(this.ahead, this.position(t));
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
   * A reported `pose`; `target` is the destination's pose while driving, else null; `route`
   * the path the robot planned to it (points, the target last), when it reported one.
   * @param {ReportedPose} pose
   * @param {Point | null} target
   * @param {Point[] | null} [route]
   */
  report(pose, target, route = null) {
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
    const path = !target ? [] : route && route.length ? [...route] : [target];
    if (target && distance(path[path.length - 1], target) > 1e-6) path.push(target);
    const reportedAhead = ahead(path, pose);
    let anchor = { x: pose.x, y: pose.y, t };
    let aheadOfAnchor = reportedAhead;
    if (target && length(shown, ahead(path, shown)) < length(pose, reportedAhead)) {
      // The robot is behind where it was drawn: hold the drawn place rather than back up;
      // the speed just measured lets the report catch up.
      anchor = { x: shown.x, y: shown.y, t };
      aheadOfAnchor = ahead(path, shown);
    }
    this.offset = { x: shown.x - anchor.x, y: shown.y - anchor.y, t };
    this.anchor = anchor;
    this.target = target;
    this.ahead = aheadOfAnchor;
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
      const next = this.remaining(t).find((point) => distance(at, point) > 0.05);
      if (next) wanted = Math.atan2(next.y - at.y, next.x - at.x);
    }
    const step = TURN_RATE * dt;
    const delta = angleDelta(this.heading, wanted);
    this.heading += Math.abs(delta) <= step ? delta : Math.sign(delta) * step;
    return this.heading;
  }
}

/**
 * The point `metres` along the way from `from` through `points`, or the last point.
 * @param {Point} from @param {Point[]} points @param {number} metres @returns {Point}
 */
function walk(from, points, metres) {
  let here = from, left = Math.max(metres, 0);
  for (const point of points) {
    const leg = distance(here, point);
    if (left <= leg) {
      if (leg < 1e-9) return { x: point.x, y: point.y };
      return { x: here.x + ((point.x - here.x) * left) / leg, y: here.y + ((point.y - here.y) * left) / leg };
    }
    left -= leg;
    here = point;
  }
  return { x: here.x, y: here.y };
}

/**
 * The points of `path` still ahead of `at`: those after the leg nearest to it (a straight
 * way, one point, is all ahead).
 * @param {Point[]} path @param {Point} at @returns {Point[]}
 */
export function ahead(path, at) {
  if (path.length <= 1) return path;
  let best = 0, nearest = Infinity;
  for (let i = 0; i + 1 < path.length; i += 1) {
    const d = toSegment(at, path[i], path[i + 1]);
    if (d < nearest - 1e-9) { nearest = d; best = i; }
  }
  return path.slice(best + 1);
}

/** The length of the way from `from` through `points`. @param {Point} from @param {Point[]} points */
function length(from, points) {
  let total = 0, here = from;
  for (const point of points) { total += distance(here, point); here = point; }
  return total;
}

/** The distance from `p` to the segment a-b. @param {Point} p @param {Point} a @param {Point} b */
function toSegment(p, a, b) {
  const dx = b.x - a.x, dy = b.y - a.y;
  const span = dx * dx + dy * dy;
  const along = span > 1e-12 ? Math.min(Math.max(((p.x - a.x) * dx + (p.y - a.y) * dy) / span, 0), 1) : 0;
  return Math.hypot(p.x - (a.x + along * dx), p.y - (a.y + along * dy));
}
