// @ts-check
// The floor, top-down, drawn from fleet.yaml, with every robot where it was last reported.
// A floor that is a map is its picture (the occupancy image, at the map's scale) under the
// robots, zoomed to the part that is not unknown; a moving robot's planned path is drawn
// ahead of it, and a closed zone (and its area) is drawn as closed.
//
// Up to `SVG_ROBOTS_UP_TO` robots each is an SVG group, a button with its name for screen
// readers; more are drawn on one canvas over the floor (robot-layer.js), clustered where
// they crowd, and found by name in the robots panel's search.
//
// Robots report their pose now and then, so between reports the map moves each robot
// along its path (motion.js): toward its destination zone at the speed its reports imply,
// easing into a report that disagrees, never jumping or sliding back.

import { clock } from "./dom.js";
import { Motion, angleDelta, distance } from "./motion.js";
import { RobotLayer } from "./robot-layer.js";

/** @import { Conveyor, Event, FleetView, FloorMap, Point, Pose, Reported, RobotEntry, RobotView, ZoneEntry } from "./contract.js" */
/** @import { ReportedPose } from "./motion.js" */

/**
 * What the map and the robots panel show of one robot.
 * @typedef {object} RobotState
 * @property {string} status "offline", or the reported status ("idle" before any)
 * @property {Reported} reported
 * @property {boolean | null} [online]
 * @property {number | null} [lastSeen]
 * @property {Event | null} [progress]
 */

/**
 * One robot's parts on the map.
 * @typedef {object} DrawnRobot
 * @property {SVGGElement} group
 * @property {SVGGElement} rotor
 * @property {SVGCircleElement} body
 * @property {SVGRectElement} cargo
 * @property {SVGTextElement | null} label
 * @property {SVGTextElement | null} detail
 * @property {SVGPolylineElement} path
 * @property {SVGCircleElement} destination
 * @property {Motion} motion
 * @property {Partial<RobotState>} state
 * @property {string} [colour]
 * @property {string} [labelAt]
 */

/** @typedef {"floor" | "fixtures" | "zones" | "paths" | "robots"} Layer */

const SVG = "http://www.w3.org/2000/svg";
const LABELS_UP_TO = 12; // more robots than this: numbers only, no names under them
// Frames a second the map moves robots at: smooth for a few, calmer (and cheaper) for many.
const FRAME_MS_FEW = 0, FRAME_MS_MANY = 50, MANY = 20;
// More robots than this are drawn on a canvas: SVG's per-element styling and layout cost
// grows with every robot drawn each frame.
export const SVG_ROBOTS_UP_TO = 24;

/**
 * @template {keyof SVGElementTagNameMap} K
 * @param {K} name
 * @param {Record<string, string | number>} [attributes]
 * @param {Element | null} [parent]
 * @returns {SVGElementTagNameMap[K]}
 */
function el(name, attributes = {}, parent = null) {
  const node = document.createElementNS(SVG, name);
  for (const [key, value] of Object.entries(attributes)) node.setAttribute(key, String(value));
  if (parent) parent.appendChild(node);
  return node;
}

// Write an attribute only when its value changes: every write, even of the same value,
// makes the browser restyle and lay the map out again.
/** @param {Element} node @param {string} name @param {string | number} value */
function put(node, name, value) {
  const text = String(value);
  if (node.getAttribute(name) !== text) node.setAttribute(name, text);
}

const now = () => performance.now();

export class MapView {
  /**
   * @param {SVGSVGElement} svg
   * @param {{onRobot: (thing: string) => void, onZone: (zone: string) => void}} handlers
   */
  constructor(svg, { onRobot, onZone }) {
    this.svg = svg;
    this.onRobot = onRobot;
    this.onZone = onZone;
    /** @type {Map<string, DrawnRobot>} */
    this.robots = new Map();
    /** @type {Map<string, {group: SVGGElement, zone: ZoneEntry, half: number, area: SVGPolygonElement | null}>} */
    this.zones = new Map();
    /** The zones closed now. @type {Set<string>} */
    this.closed = new Set();
    /** @type {Map<string, SVGGElement>} */
    this.arms = new Map();
    /** @type {number | null} */
    this.frame = null;
    this.lastFrame = 0;
    /** @type {string | null} */
    this.selected = null;
    /** @type {FleetView | undefined} */
    this.fleet = undefined;
    this.scale = 1;
    this.labels = true;
    /** @type {SVGGElement | null} */
    this.led = null;
    /** Set for a fleet too large for SVG robots. @type {RobotLayer | null} */
    this.layer = null;
  }

  // -- drawing the floor ---------------------------------------------------------------

  /** @param {FleetView} fleet */
  build(fleet) {
    this.fleet = fleet;
    this.svg.replaceChildren();
    this.layer?.remove();
    this.layer = fleet.robots.length > SVG_ROBOTS_UP_TO ? new RobotLayer(this.svg, this.onRobot) : null;
    this.robots.clear();
    this.zones.clear();
    this.arms.clear();
    const floor = fleet.floor;
    const width = floor.width ?? 0, height = floor.height ?? 0;
    // A map is drawn around the part of it that is not unknown space; a drawn floor whole.
    const shown = fleet.map
      ? fleet.map.known
      : { left: floor.origin.x, bottom: floor.origin.y, right: floor.origin.x + width, top: floor.origin.y + height };
    const xs = [shown.left, shown.right];
    const ys = [shown.bottom, shown.top];
    for (const robot of fleet.robots) { xs.push(robot.start.x); ys.push(robot.start.y); }
    for (const zone of fleet.zones) {
      xs.push(zone.pose.x - zone.radius, zone.pose.x + zone.radius);
      ys.push(zone.pose.y - zone.radius, zone.pose.y + zone.radius);
    }
    const margin = 0.45;
    const left = Math.min(...xs) - margin, right = Math.max(...xs) + margin;
    const bottom = Math.min(...ys) - margin, top = Math.max(...ys) + margin + 0.35;
    // Map y points up; SVG's points down: every y is drawn as -y.
    this.svg.setAttribute("viewBox", `${left} ${-top} ${right - left} ${top - bottom}`);
    this.svg.setAttribute("preserveAspectRatio", "xMidYMid meet");
    this.scale = Math.max(1, Math.max(right - left, top - bottom) / 13);
    this.labels = fleet.robots.length <= LABELS_UP_TO;

    const layers = /** @type {Record<Layer, SVGGElement>} */ ({});
    for (const name of /** @type {Layer[]} */ (["floor", "fixtures", "zones", "paths", "robots"])) layers[name] = el("g", { class: `layer-${name}` }, this.svg);
    this.layers = layers;

    if (fleet.map) {
      this.drawMap(fleet.map, layers.floor);
    } else {
      el("rect", { class: "floor", x: floor.origin.x, y: -(floor.origin.y + height), width, height }, layers.floor);
      for (let x = Math.ceil(floor.origin.x); x < floor.origin.x + width; x += 1) {
        el("line", { class: "grid-line", x1: x, x2: x, y1: -floor.origin.y, y2: -(floor.origin.y + height) }, layers.floor);
      }
      for (let y = Math.ceil(floor.origin.y); y < floor.origin.y + height; y += 1) {
        el("line", { class: "grid-line", y1: -y, y2: -y, x1: floor.origin.x, x2: floor.origin.x + width }, layers.floor);
      }
    }
    for (const wall of floor.walls) {
      el("line", { class: "wall", x1: wall.start.x, y1: -wall.start.y, x2: wall.end.x, y2: -wall.end.y }, layers.floor);
    }
    if (floor.conveyor) this.drawConveyor(floor.conveyor, layers.fixtures);
    for (const zone of fleet.zones) this.drawZone(zone, layers.zones);
    for (const [zoneId, at] of Object.entries(floor.arms || {})) this.drawArm(zoneId, at, layers.fixtures);
    if (floor.led) this.drawLed(floor.led, layers.fixtures);
    const layer = this.layer;
    if (layer) {
      for (const robot of fleet.robots) layer.add(robot.thing, robot.start);
      this.animate();
    } else {
      fleet.robots.forEach((robot, index) => this.drawRobot(robot, index, layers));
    }
  }

  // The map's picture: one image, a pixel a cell, laid at the map's origin and scale (its
  // first row is the map's top); unknown space is clear, so the page shows through.
  /** @param {FloorMap} map @param {SVGGElement} parent */
  drawMap(map, parent) {
    const width = map.columns * map.resolution, height = map.rows * map.resolution;
    const { known } = map;
    el("rect", { class: "floor map-ground", x: known.left, y: -known.top, width: known.right - known.left, height: known.top - known.bottom }, parent);
    const image = el("image", { class: "floor-map", href: map.image, x: map.origin.x, y: -(map.origin.y + height), width, height, preserveAspectRatio: "none" }, parent);
    el("title", {}, image).textContent = "The map the robots plan on";
  }

  /** @param {Conveyor} conveyor @param {SVGGElement} parent */
  drawConveyor(conveyor, parent) {
    const { start, end, width } = conveyor;
    const length = distance(start, end);
    const angle = (-Math.atan2(end.y - start.y, end.x - start.x) * 180) / Math.PI;
    const group = el("g", { class: "conveyor", transform: `translate(${start.x} ${-start.y}) rotate(${angle})` }, parent);
    el("title", {}, group).textContent = "Conveyor";
    el("rect", { class: "conveyor-belt", x: 0, y: -width / 2, width: length, height: width, rx: 0.04 }, group);
    for (let s = 0.18; s < length - 0.05; s += 0.26) {
      const h = width * 0.28;
      el("path", { class: "conveyor-chevron", d: `M ${s} ${-h} L ${s + 0.1} 0 L ${s} ${h}` }, group);
    }
  }

  /** @param {ZoneEntry} zone @param {SVGGElement} parent */
  drawZone(zone, parent) {
    // The box is the arrival circle's square with room around it; a robot stops at its
    // centre, so the letter sits in the top-left corner and the name along the bottom.
    const half = zone.radius + 0.22;
    const { x, y } = zone.pose;
    const area = zone.area ? el("polygon", { class: "zone-area", "data-zone": zone.id, points: zone.area.map((p) => `${p.x},${-p.y}`).join(" ") }, parent) : null;
    const group = el("g", { class: `zone${zone.arm === "loader" ? " loading" : ""}`, "data-zone": zone.id, role: "button", "aria-label": `Zone ${zone.name}` }, parent);
    el("title", {}, group).textContent = zone.name;
    el("rect", { class: "zone-body", x: x - half, y: -y - half, width: 2 * half, height: 2 * half, rx: 0.16 }, group);
    const big = zone.id.length <= 2 ? zone.id : zone.key;
    const letter = el("text", { class: "zone-letter", x: x - half + 0.26, y: -y - half + 0.3, "font-size": big ? 0.42 : 0.2 }, group);
    letter.textContent = big || zone.name;
    if (!big) letter.setAttribute("x", String(x));
    const name = el("text", { class: "zone-name", x, y: -y + half - 0.09, "font-size": 0.16 }, group);
    name.textContent = zone.name;
    group.addEventListener("click", () => this.onZone(zone.id));
    this.zones.set(zone.id, { group, zone, half, area });
    this.showClosed(zone.id);
  }

  // The zones closed now: each is drawn crossed out, its area hatched.
  /** @param {string[]} closed */
  setClosed(closed) {
    this.closed = new Set(closed);
    for (const zoneId of this.zones.keys()) this.showClosed(zoneId);
  }

  /** @param {string} zoneId */
  showClosed(zoneId) {
    const drawn = this.zones.get(zoneId);
    if (!drawn) return;
    const closed = this.closed.has(zoneId);
    drawn.group.classList.toggle("closed", closed);
    drawn.area?.classList.toggle("closed", closed);
    put(drawn.group, "aria-label", `Zone ${drawn.zone.name}${closed ? " (closed)" : ""}`);
  }

  /** @param {string} zoneId @param {Point} at @param {SVGGElement} parent */
  drawArm(zoneId, at, parent) {
    const zone = this.fleet?.zones.find((z) => z.id === zoneId);
    if (!zone) return;
    const group = el("g", { class: "arm" }, parent);
    el("title", {}, group).textContent = zone.arm === "loader" ? "Loading arm" : `Unloading arm of zone ${zone.id}`;
    const length = Math.min(0.45, distance(at, zone.pose) * 0.6);
    const toward = Math.atan2(zone.pose.y - at.y, zone.pose.x - at.x);
    el("line", { class: "arm-link", x1: at.x, y1: -at.y, x2: at.x + length * Math.cos(toward), y2: -(at.y + length * Math.sin(toward)) }, group);
    el("circle", { class: "arm-base", cx: at.x, cy: -at.y, r: 0.12 }, group);
    this.arms.set(zoneId, group);
  }

  /** @param {Point} at @param {SVGGElement} parent */
  drawLed(at, parent) {
    const group = el("g", { class: "led" }, parent);
    el("title", {}, group).textContent = "Task III LED: lights when both robots delivered to D in order";
    el("circle", { class: "led-body", cx: at.x, cy: -at.y, r: 0.13 }, group);
    el("text", { class: "led-label", x: at.x - 0.22, y: -at.y + 0.06, "font-size": 0.17, "text-anchor": "end" }, group).textContent = "task III LED";
    this.led = group;
  }

  /** @param {RobotEntry} robot @param {number} index @param {Record<Layer, SVGGElement>} layers */
  drawRobot(robot, index, layers) {
    const group = el("g", { class: "robot", "data-thing": robot.thing, role: "button", "aria-label": robot.name }, layers.robots);
    el("title", {}, group).textContent = robot.name;
    el("circle", { class: "robot-alert", r: 0.38 }, group);
    el("circle", { class: "robot-ring", r: 0.42 }, group);
    const rotor = el("g", {}, group);
    const body = el("circle", { class: "robot-body", r: 0.28 }, rotor);
    el("path", { class: "robot-nose", d: "M 0.25 0 L 0.09 0.1 L 0.09 -0.1 Z" }, rotor);
    const number = el("text", { class: "robot-number", "font-size": 0.24, y: 0.01 }, group);
    number.textContent = robot.key ?? String(index + 1);
    const cargo = el("rect", { class: "robot-cargo", x: 0.14, y: -0.42, width: 0.2, height: 0.2, rx: 0.04, visibility: "hidden" }, group);
    let label = null, detail = null;
    if (this.labels) {
      label = el("text", { class: "robot-label", y: -0.03, "font-size": 0.22 * this.scale }, group);
      label.textContent = robot.name;
      detail = el("text", { class: "robot-detail", y: 0.22 * this.scale, "font-size": 0.18 * this.scale }, group);
    }
    const path = el("polyline", { class: "path", visibility: "hidden" }, layers.paths);
    const destination = el("circle", { class: "destination", r: 0.36, visibility: "hidden" }, layers.paths);
    group.addEventListener("click", (event) => { event.stopPropagation(); this.onRobot(robot.thing); });
    const motion = new Motion(robot.start);
    this.robots.set(robot.thing, { group, rotor, body, cargo, label, detail, path, destination, motion, state: {} });
    this.place(robot.thing, now(), 0);
  }

  // -- state ---------------------------------------------------------------------------

  /** @param {string | null | undefined} zoneId @returns {Pose | null} */
  zonePose(zoneId) {
    if (!zoneId) return null;
    return this.zones.get(zoneId)?.zone.pose ?? null;
  }

  // A robot's whole state changed (shadow, presence, an event): redraw what it shows.
  /** @param {string} thing @param {RobotView} robot */
  update(thing, robot) {
    if (this.layer) {
      this.layer.update(thing, robot.online === false ? "offline" : robot.reported?.status || "idle", Boolean(robot.reported?.cargo));
      return;
    }
    const drawn = this.robots.get(thing);
    if (!drawn) return;
    /** @type {Reported} */
    const reported = robot.reported || {};
    const status = robot.online === false ? "offline" : reported.status || "idle";
    drawn.state = { status, reported, online: robot.online, lastSeen: robot.last_seen, progress: robot.progress };
    drawn.group.classList.toggle("offline", robot.online === false);
    const colour = `var(--${statusColour(status)})`;
    if (drawn.colour !== colour) {
      drawn.colour = colour;
      drawn.body.style.fill = drawn.path.style.stroke = drawn.destination.style.stroke = colour;
    }
    put(drawn.cargo, "visibility", reported.cargo ? "visible" : "hidden");
    if (drawn.detail) {
      const text = describe(/** @type {RobotState} */ (drawn.state));
      if (drawn.detail.textContent !== text) drawn.detail.textContent = text;
    }
  }

  // A reported pose (from the shadow or an event): move the robot's motion, along the path
  // it planned when it reported one.
  /**
   * @param {string} thing
   * @param {ReportedPose | null | undefined} pose
   * @param {string | null | undefined} destinationZone
   * @param {boolean} driving
   * @param {Array<[number, number]> | null} [path] the shadow's `path`
   */
  report(thing, pose, destinationZone, driving, path = null) {
    const drawn = this.layer ? this.layer.robots.get(thing) : this.robots.get(thing);
    if (!drawn || !pose) return;
    const end = path && path.length ? { x: path[path.length - 1][0], y: path[path.length - 1][1] } : null;
    const target = driving ? end || this.zonePose(destinationZone) : null;
    const route = driving && path ? path.map(([x, y]) => ({ x, y })) : null;
    drawn.motion.report(pose, target, route);
    this.animate();
  }

  // The robots with an open alert, and about what: each is ringed in its trouble's colour.
  /** @param {Map<string, string>} troubled */
  setTroubled(troubled) {
    if (this.layer) {
      this.layer.troubled = troubled;
      this.layer.dirty = true;
      this.animate();
    }
    for (const [thing, drawn] of this.robots) {
      const trouble = troubled.get(thing);
      drawn.group.classList.toggle("alerting", Boolean(trouble));
      if (trouble) put(drawn.group, "data-trouble", trouble);
    }
  }

  /** @param {boolean | undefined} on */
  setLed(on) {
    this.led?.classList.toggle("on", Boolean(on));
  }

  /** @param {string | null} thing */
  select(thing) {
    this.selected = thing;
    if (this.layer) {
      this.layer.selected = thing;
      this.layer.dirty = true;
      this.animate();
    }
    for (const [name, drawn] of this.robots) drawn.group.classList.toggle("selected", name === thing);
    this.svg.classList.toggle("map-armed", Boolean(thing));
  }

  // The arms at work: call once after the robots of a frame were updated.
  updateArms() {
    const working = new Set();
    for (const drawn of this.robots.values()) {
      const { status, reported } = drawn.state;
      if ((status === "loading" || status === "unloading") && reported?.zone) working.add(reported.zone);
    }
    // A robot's new status is painted in the frame it arrived in, not the next slow tick.
    if (this.layer?.dirty) this.layer.draw(now());
    for (const [zoneId, arm] of this.arms) arm.classList.toggle("working", working.has(zoneId));
  }

  // -- moving ----------------------------------------------------------------------------

  animate() {
    if (this.frame === null) {
      this.frame = requestAnimationFrame(() => this.tick());
    }
  }

  tick() {
    this.frame = null;
    const t = now();
    const every = this.robots.size > MANY || this.layer ? FRAME_MS_MANY : FRAME_MS_FEW;
    if (t - this.lastFrame < every) {
      this.animate();
      return;
    }
    const dt = Math.min(0.1, (t - this.lastFrame) / 1000);
    this.lastFrame = t;
    if (this.layer) {
      if (this.layer.draw(t)) this.animate();
      return;
    }
    let busy = false;
    for (const thing of this.robots.keys()) busy = this.place(thing, t, dt) || busy;
    if (busy) this.animate();
  }

  // Draw one robot at time t; true while it is still moving (or settling, or turning).
  /** @param {string} thing @param {number} t @param {number} dt */
  place(thing, t, dt) {
    const drawn = this.robots.get(thing);
    if (!drawn) return false;
    const { motion } = drawn;
    const at = motion.position(t);
    const heading = motion.headingAt(t, dt);
    put(drawn.group, "transform", `translate(${at.x.toFixed(3)} ${(-at.y).toFixed(3)})`);
    if (drawn.label) this.placeLabel(drawn, at);
    put(drawn.rotor, "transform", `rotate(${((-heading * 180) / Math.PI).toFixed(1)})`);
    const target = motion.target;
    const show = target && distance(at, target) > 0.05 ? "visible" : "hidden";
    put(drawn.path, "visibility", show);
    put(drawn.destination, "visibility", show);
    if (target) {
      // The way still ahead: from where the robot is drawn through the corners to come.
      const ahead = [at, ...motion.remaining(t)];
      put(drawn.path, "points", ahead.map((p) => `${p.x.toFixed(3)},${(-p.y).toFixed(3)}`).join(" "));
      put(drawn.destination, "cx", target.x);
      put(drawn.destination, "cy", -target.y);
    }
    const turning = Math.abs(angleDelta(motion.heading, motion.target ? heading : motion.theta)) > 0.01;
    return motion.driving || motion.settling || turning;
  }

  // Names go beside a robot on the side facing the middle of the floor, clear of the zone
  // it stands in, so they never cover a zone's letter.
  /** @param {DrawnRobot} drawn @param {Point} at */
  placeLabel(drawn, at) {
    const floor = this.fleet?.floor;
    if (!floor) return;
    const known = this.fleet?.map?.known;
    const middle = known ? (known.left + known.right) / 2 : floor.origin.x + (floor.width ?? 0) / 2;
    const side = at.x > middle ? -1 : 1;
    let offset = 0.42;
    for (const { zone, half } of this.zones.values()) {
      if (Math.abs(at.x - zone.pose.x) <= half && Math.abs(at.y - zone.pose.y) <= half) {
        offset = Math.max(offset, side * (zone.pose.x - at.x) + half + 0.1);
      }
    }
    const x = (side * offset).toFixed(3);
    const anchor = side > 0 ? "start" : "end";
    if (drawn.labelAt === `${x}${anchor}`) return;
    drawn.labelAt = `${x}${anchor}`;
    for (const text of [drawn.label, drawn.detail]) {
      text?.setAttribute("x", x);
      text?.setAttribute("text-anchor", anchor);
    }
  }

  // Where a robot is drawn now (tests and benchmarks read it).
  /** @param {string} thing */
  drawnPosition(thing) {
    const drawn = this.layer ? this.layer.robots.get(thing) : this.robots.get(thing);
    return drawn ? drawn.motion.position(now()) : null;
  }
}

/** The colour (a CSS variable's name) of each status. @type {Record<string, string>} */
const STATUS_COLOURS = {
  idle: "idle",
  navigating: "navigating",
  loading: "loading",
  unloading: "loading",
  waiting: "waiting",
  stopped: "stopped",
  stuck: "stuck",
  error: "error",
  offline: "offline",
};

/** @param {string} status */
export function statusColour(status) {
  return STATUS_COLOURS[status] || "idle";
}

/** @type {Record<string, string>} */
const zoneNames = {};

/** @param {ZoneEntry[]} zones */
export function setZoneNames(zones) {
  for (const zone of zones) zoneNames[zone.id] = zone.name;
}

// How a zone is named in running text: its id when it is a letter ("B"), else its name.
/** @param {string | null | undefined} id */
export function zoneText(id) {
  if (!id) return "";
  return id.length <= 2 || !zoneNames[id] ? id : zoneNames[id];
}

/** @param {RobotState} state @param {{where?: boolean}} [options] */
export function describe(state, { where = true } = {}) {
  const { status, reported } = state;
  if (status === "offline") {
    return `offline · last seen ${clock(state.lastSeen, "never")}`;
  }
  if (status === "navigating") {
    const fraction = state.progress?.progress;
    const to = reported.destination ? `to ${zoneText(reported.destination)}` : "driving";
    return fraction !== undefined && fraction !== null ? `${to} · ${Math.round(fraction * 100)}%` : to;
  }
  if (status === "idle") return where && reported.zone ? `at ${zoneText(reported.zone)}` : "idle";
  if (status === "loading") return "loading";
  if (status === "unloading") return `unloading at ${zoneText(reported.zone)}`;
  return status;
}
