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
import { t } from "./i18n.js";
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

/**
 * One zone's parts on the map.
 * @typedef {object} DrawnZone
 * @property {SVGGElement} group
 * @property {ZoneEntry} zone
 * @property {number} half half its box's side, in metres
 * @property {SVGRectElement} body
 * @property {SVGTextElement} letter
 * @property {SVGTextElement} name
 * @property {SVGTextElement} incoming
 * @property {SVGPolygonElement | null} area its area, when the fleet gives it one
 * @property {boolean} big whether its letter is its id or key (else its name, small)
 */

const SVG = "http://www.w3.org/2000/svg";
const LABELS_UP_TO = 12; // more robots than this: numbers only, no names under them
// A zone's letter and name are this many screen pixels high, and its box at least this many
// across, whatever the floor's size: a thousand robots' floor is as readable as four's.
const ZONE_LETTER_PX = 18, ZONE_NAME_PX = 12, ZONE_BOX_PX = 34;
// How often the map moves robots: 30 frames a second for a few (a robot at 0.5 m/s moves
// under a pixel a frame at 30 on the default floor in a laptop's window, so the screen's 60
// add nothing one can see, and cost an open page half as much CPU again while two robots
// drove), 20 for many.
const FRAME_MS_FEW = 33, FRAME_MS_MANY = 50, MANY = 20;
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
    /** @type {Map<string, DrawnZone>} */
    this.zones = new Map();
    /** The zones closed now. @type {Set<string>} */
    this.closed = new Set();
    // The floor's size on the screen decides how large a zone's words are drawn.
    this.resized = new ResizeObserver(() => this.sizeZones());
    this.resized.observe(svg);
    // Where each robot of a large fleet is heading (a zone id), for the zones' counts.
    /** @type {Map<string, string>} */
    this.heading = new Map();
    this.headingChanged = false;
    // Metres a screen pixel spans on the floor as drawn, and the floor's drawn extent.
    this.metresPerPx = 0.025;
    /** @type {{width: number, height: number} | null} */
    this.extent = null;
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
    this.extent = { width: right - left, height: top - bottom };
    this.measure();
    this.heading.clear();
    showLegend(".legend-crowd", fleet.robots.length > SVG_ROBOTS_UP_TO);
    showLegend(".legend-key", fleet.robots.length <= SVG_ROBOTS_UP_TO);

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
    this.svg.classList.toggle("map-crowded", Boolean(layer));
    if (layer) {
      for (const robot of fleet.robots) layer.add(robot.thing, robot.start);
      layer.labels = [...this.zones.values()].map(({ zone, half }) => ({
        below: { x: zone.pose.x, y: zone.pose.y - half },
        above: { x: zone.pose.x, y: zone.pose.y + half },
        name: zone.name,
        incoming: "",
      }));
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
    el("title", {}, image).textContent = t("The map the robots plan on");
  }

  /** @param {Conveyor} conveyor @param {SVGGElement} parent */
  drawConveyor(conveyor, parent) {
    const { start, end, width } = conveyor;
    const length = distance(start, end);
    const angle = (-Math.atan2(end.y - start.y, end.x - start.x) * 180) / Math.PI;
    const group = el("g", { class: "conveyor", transform: `translate(${start.x} ${-start.y}) rotate(${angle})` }, parent);
    el("title", {}, group).textContent = t("Conveyor");
    el("rect", { class: "conveyor-belt", x: 0, y: -width / 2, width: length, height: width, rx: 0.04 }, group);
    for (let s = 0.18; s < length - 0.05; s += 0.26) {
      const h = width * 0.28;
      el("path", { class: "conveyor-chevron", d: `M ${s} ${-h} L ${s + 0.1} 0 L ${s} ${h}` }, group);
    }
  }

  /** @param {ZoneEntry} zone @param {SVGGElement} parent */
  drawZone(zone, parent) {
    const area = zone.area ? el("polygon", { class: "zone-area", "data-zone": zone.id, points: zone.area.map((p) => `${p.x},${-p.y}`).join(" ") }, parent) : null;
    const group = el("g", { class: `zone${zone.arm === "loader" ? " loading" : ""}`, "data-zone": zone.id, role: "button", "aria-label": zone.name }, parent);
    el("title", {}, group).textContent = zone.name;
    const body = el("rect", { class: "zone-body" }, group);
    const shown = zone.id.length <= 2 ? zone.id : zone.key;
    const letter = el("text", { class: "zone-letter" }, group);
    letter.textContent = shown || zone.name;
    const name = el("text", { class: "zone-name" }, group);
    name.textContent = zone.name;
    // How many robots are on their way here (a large fleet's robots draw no paths).
    const incoming = el("text", { class: "zone-incoming", visibility: "hidden" }, group);
    group.addEventListener("click", () => this.onZone(zone.id));
    const drawn = { group, zone, half: zone.radius + 0.22, area, body, letter, name, incoming, big: Boolean(shown) };
    this.zones.set(zone.id, drawn);
    this.sizeZone(drawn);
    this.showClosed(zone.id);
  }

  // The floor's metres per screen pixel, as drawn now ("meet": as large as the box allows).
  measure() {
    const box = this.svg.getBoundingClientRect();
    const { width, height } = this.extent ?? { width: 0, height: 0 };
    const fit = width > 0 && height > 0 ? Math.min(box.width / width, box.height / height) : 0;
    this.metresPerPx = fit > 0 ? 1 / fit : this.scale / 40;
  }

  // The zones drawn again at the floor's size on the screen now.
  sizeZones() {
    if (!this.fleet) return;
    this.measure();
    for (const drawn of this.zones.values()) this.sizeZone(drawn);
    if (this.layer) {
      for (const label of this.layer.labels) {
        const drawn = [...this.zones.values()].find((z) => z.zone.name === label.name);
        if (!drawn) continue;
        label.below = { x: drawn.zone.pose.x, y: drawn.zone.pose.y - drawn.half };
        label.above = { x: drawn.zone.pose.x, y: drawn.zone.pose.y + drawn.half };
      }
      this.layer.dirty = true;
      this.animate();
    }
  }

  // The box is the arrival circle's square with room around it; a robot stops at its
  // centre, so the letter (or key) sits in the top-left corner and the name along the
  // bottom. On a large floor a box would be a speck: it is at least ZONE_BOX_PX across, its
  // letter and name ZONE_LETTER_PX and ZONE_NAME_PX high, the name then below the box.
  /** @param {DrawnZone} drawn */
  sizeZone(drawn) {
    const px = this.metresPerPx;
    const { zone, body, letter, name, incoming, big } = drawn;
    const half = Math.max(zone.radius + 0.22, (ZONE_BOX_PX / 2) * px);
    drawn.half = half;
    const letterSize = Math.max(0.42, ZONE_LETTER_PX * px), nameSize = Math.max(0.16, ZONE_NAME_PX * px);
    const { x, y } = zone.pose;
    for (const [key, value] of Object.entries({ x: x - half, y: -y - half, width: 2 * half, height: 2 * half, rx: Math.min(0.16 * this.scale, half / 3) })) put(body, key, value);
    put(letter, "x", big ? x - half + 0.6 * letterSize : x);
    put(letter, "y", -y - half + 0.72 * letterSize);
    put(letter, "font-size", big ? letterSize : nameSize);
    const inside = nameSize <= 0.2;
    name.classList.toggle("below", !inside);
    put(name, "x", x);
    put(name, "y", inside ? -y + half - 0.09 : -y + half + 0.2 * nameSize);
    put(name, "font-size", nameSize);
    put(incoming, "x", x);
    put(incoming, "y", -y - half - 0.35 * nameSize);
    put(incoming, "font-size", nameSize);
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
    put(drawn.group, "aria-label", closed ? t("{zone} (closed)", { zone: drawn.zone.name }) : drawn.zone.name);
  }

  /** @param {string} zoneId @param {Point} at @param {SVGGElement} parent */
  drawArm(zoneId, at, parent) {
    const zone = this.fleet?.zones.find((z) => z.id === zoneId);
    if (!zone) return;
    const group = el("g", { class: "arm" }, parent);
    el("title", {}, group).textContent = zone.arm === "loader" ? t("Loading arm") : t("Unloading arm of {zone}", { zone: zone.name });
    const length = Math.min(0.45, distance(at, zone.pose) * 0.6);
    const toward = Math.atan2(zone.pose.y - at.y, zone.pose.x - at.x);
    el("line", { class: "arm-link", x1: at.x, y1: -at.y, x2: at.x + length * Math.cos(toward), y2: -(at.y + length * Math.sin(toward)) }, group);
    el("circle", { class: "arm-base", cx: at.x, cy: -at.y, r: 0.12 }, group);
    this.arms.set(zoneId, group);
  }

  /** @param {Point} at @param {SVGGElement} parent */
  drawLed(at, parent) {
    const group = el("g", { class: "led" }, parent);
    el("title", {}, group).textContent = t("Task III LED: lights when both robots delivered to D in order");
    el("circle", { class: "led-body", cx: at.x, cy: -at.y, r: 0.13 }, group);
    el("text", { class: "led-label", x: at.x - 0.22, y: -at.y + 0.06, "font-size": 0.17, "text-anchor": "end" }, group).textContent = t("task III LED");
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
      const status = robot.online === false ? "offline" : robot.reported?.status || "idle";
      this.layer.update(thing, status, Boolean(robot.reported?.cargo));
      const goal = status === "navigating" ? robot.reported?.destination : null;
      if ((this.heading.get(thing) ?? null) !== (goal ?? null)) {
        if (goal) this.heading.set(thing, goal);
        else this.heading.delete(thing);
        this.headingChanged = true;
      }
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
    if (this.headingChanged) this.countIncoming();
    for (const [zoneId, arm] of this.arms) arm.classList.toggle("working", working.has(zoneId));
  }

  // Each zone says how many robots are on their way to it ("→ 1,000"): a large fleet's
  // motion is a crowd of dots, and this is where it is going.
  countIncoming() {
    this.headingChanged = false;
    /** @type {Map<string, number>} */
    const counts = new Map();
    for (const zone of this.heading.values()) counts.set(zone, (counts.get(zone) ?? 0) + 1);
    for (const [id, { incoming, zone }] of this.zones) {
      const count = counts.get(id) ?? 0;
      put(incoming, "visibility", count ? "visible" : "hidden");
      if (incoming.dataset.count === String(count)) continue;
      incoming.dataset.count = String(count);
      const shown = count.toLocaleString("en-US");
      const title = el("title");
      title.textContent = t("{count} robots on their way to {zone}", { count: shown, zone: zone.name });
      incoming.replaceChildren(document.createTextNode(count ? `→ ${shown}` : ""), title);
      const label = this.layer?.labels.find((l) => l.name === zone.name);
      if (label) {
        label.incoming = count ? `→ ${shown}` : "";
        if (this.layer) this.layer.dirty = true;
      }
    }
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
    return t("offline · last seen {when}", { when: clock(state.lastSeen, t("never")) });
  }
  if (status === "navigating") {
    const fraction = state.progress?.progress;
    const to = reported.destination ? t("to {zone}", { zone: zoneText(reported.destination) }) : t("driving");
    return fraction !== undefined && fraction !== null ? `${to} · ${Math.round(fraction * 100)}%` : to;
  }
  if (status === "idle") return where && reported.zone ? t("at {zone}", { zone: zoneText(reported.zone) }) : t("idle");
  if (status === "loading") return t("loading");
  if (status === "unloading") return t("unloading at {zone}", { zone: zoneText(reported.zone) });
  return t(status);
}

/**
 * A robot's reason as a person reads it: the zone it names by id (`zoneId`, the zone its
 * command was for) by the zone's name, unless the name is said already ("no path to zone
 * A"). As the skill says it (vahr.domain.fleet.reason_said).
 * @param {string} reason
 * @param {string | null | undefined} zoneId
 */
export function reasonSaid(reason, zoneId) {
  const name = zoneId ? zoneNames[zoneId] : undefined;
  if (!zoneId || !name) return reason;
  const lead = name.toLowerCase().endsWith(zoneId.toLowerCase()) ? name.slice(0, name.length - zoneId.length).toLowerCase() : null;
  const id = zoneId.replace(/[.*+?^${}()|[\]\\]/g, "\\$&");
  return reason.replace(new RegExp(`(?<![A-Za-z0-9_])${id}(?![A-Za-z0-9_])`, "g"), (match, offset) =>
    lead && reason.slice(0, offset).toLowerCase().endsWith(lead) ? match : name,
  );
}

/** Show or hide the legend's entries that `selector` finds. @param {string} selector @param {boolean} shown */
function showLegend(selector, shown) {
  for (const item of document.querySelectorAll(selector)) /** @type {HTMLElement} */ (item).hidden = !shown;
}
