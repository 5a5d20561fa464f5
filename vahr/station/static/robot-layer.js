// @ts-check
// Many robots on the map: drawn on one canvas over the floor's SVG instead of one SVG group
// each, which a browser cannot restyle and lay out at a thousand robots a frame. Robots that
// crowd on the screen are one mark with their count (cluster.js); the selected robot is
// drawn apart, ringed, with its path. A click on the map picks the mark under it before a
// zone sees the click.

import { cluster, hit } from "./cluster.js";
import { Motion } from "./motion.js";

/** @import { Cluster, Placed } from "./cluster.js" */
/** @import { Point } from "./contract.js" */

/**
 * A zone's words drawn over the robots (a crowd must not hide where it is): its name below
 * its box, and how many robots are on their way to it above.
 * @typedef {object} ZoneLabel
 * @property {Point} below the point under its box, on the floor
 * @property {Point} above the point over its box
 * @property {string} name
 * @property {string} incoming "" when none is on its way
 */

// A robot's dot, a crowd's smallest mark, and how near a click must be, in CSS pixels.
const DOT_PX = 4.5, CROWD_PX = 6.5, REACH_PX = 12;
// Robots closer than this on the screen are one mark; a crowd's mark stays inside its square.
const CELL_PX = 20;
const COLOURS = ["idle", "navigating", "loading", "waiting", "stopped", "stuck", "error", "offline", "select", "cargo"];

/**
 * One robot on the canvas.
 * @typedef {object} Dot
 * @property {Motion} motion
 * @property {string} status "offline", or the reported status
 * @property {boolean} cargo
 */

export class RobotLayer {
  /**
   * @param {SVGSVGElement} svg the floor, which the canvas covers
   * @param {(thing: string) => void} onRobot
   */
  constructor(svg, onRobot) {
    this.svg = svg;
    this.onRobot = onRobot;
    this.canvas = document.createElement("canvas");
    this.canvas.className = "robot-layer";
    this.canvas.setAttribute("aria-hidden", "true");
    svg.after(this.canvas);
    this.context = /** @type {CanvasRenderingContext2D} */ (this.canvas.getContext("2d"));
    /** @type {Map<string, Dot>} */
    this.robots = new Map();
    /** @type {Cluster[]} */
    this.marks = [];
    /** Where each robot was last drawn, in canvas pixels. @type {Map<string, Point>} */
    this.placed = new Map();
    /** @type {string | null} */
    this.selected = null;
    /** @type {Map<string, string>} */
    this.troubled = new Map();
    /** @type {Record<string, string>} */
    this.colours = {};
    /** @type {ZoneLabel[]} */
    this.labels = [];
    this.dirty = true;
    // Where the floor is on the screen, read again only when it may have moved: reading it
    // each frame would make the browser lay out the page each time a robot's line changed.
    /** @type {{box: DOMRect, matrix: DOMMatrix} | null} */
    this.frame = null;
    this.moved = () => { this.frame = null; this.dirty = true; };
    this.resized = new ResizeObserver(this.moved);
    this.resized.observe(svg);
    window.addEventListener("scroll", this.moved, { passive: true, capture: true });
    this.onClick = (/** @type {MouseEvent} */ event) => this.click(event);
    // Capture: the robot under the pointer wins over the zone it stands in.
    svg.addEventListener("click", this.onClick, true);
  }

  remove() {
    this.resized.disconnect();
    window.removeEventListener("scroll", this.moved, { capture: true });
    this.svg.removeEventListener("click", this.onClick, true);
    this.canvas.remove();
  }

  /** @param {string} thing @param {Point} start */
  add(thing, start) {
    this.robots.set(thing, { motion: new Motion(start), status: "idle", cargo: false });
  }

  /** @param {string} thing @param {string} status @param {boolean} cargo */
  update(thing, status, cargo) {
    const dot = this.robots.get(thing);
    if (!dot || (dot.status === status && dot.cargo === cargo)) return;
    dot.status = status;
    dot.cargo = cargo;
    this.dirty = true;
  }

  /** @param {MouseEvent} event */
  click(event) {
    const box = this.canvas.getBoundingClientRect();
    const x = event.clientX - box.left, y = event.clientY - box.top;
    const mark = hit(this.marks, x, y, REACH_PX);
    if (!mark) return;
    event.stopPropagation();
    // In a crowd, the robot nearest the pointer.
    let nearest = mark.things[0], best = Infinity;
    for (const thing of mark.things) {
      const at = this.placed.get(thing);
      const d = at ? (at.x - x) ** 2 + (at.y - y) ** 2 : Infinity;
      if (d < best) { best = d; nearest = thing; }
    }
    this.onRobot(nearest);
  }

  // Draw every robot at time t; true while any is still moving.
  /** @param {number} t */
  draw(t) {
    this.dirty = false;
    if (!this.frame) {
      const matrix = this.svg.getScreenCTM();
      if (!matrix) return false;
      this.frame = { box: this.svg.getBoundingClientRect(), matrix };
    }
    const { box, matrix } = this.frame;
    const ratio = window.devicePixelRatio || 1;
    const width = Math.round(box.width * ratio), height = Math.round(box.height * ratio);
    if (this.canvas.width !== width || this.canvas.height !== height) {
      this.canvas.width = width;
      this.canvas.height = height;
      this.colours = {};
    }
    if (!this.colours.idle) {
      const style = getComputedStyle(this.svg);
      for (const name of COLOURS) this.colours[name] = style.getPropertyValue(`--${name}`).trim() || "#64748b";
    }
    // SVG user units (y drawn as -y) to the canvas's CSS pixels.
    const toScreen = (/** @type {Point} */ at) => ({
      x: matrix.a * at.x - matrix.c * at.y + matrix.e - box.left,
      y: matrix.b * at.x - matrix.d * at.y + matrix.f - box.top,
    });
    let busy = false;
    /** @type {Placed[]} */
    const placed = [];
    for (const [thing, dot] of this.robots) {
      const at = toScreen(dot.motion.position(t));
      this.placed.set(thing, at);
      placed.push({ thing, x: at.x, y: at.y, status: dot.status });
      busy = busy || dot.motion.driving || dot.motion.settling;
    }
    this.marks = cluster(placed, CELL_PX, this.selected);
    const context = this.context;
    context.setTransform(ratio, 0, 0, ratio, 0, 0);
    context.clearRect(0, 0, box.width, box.height);
    context.textAlign = "center";
    context.textBaseline = "middle";
    context.font = "600 10px system-ui, sans-serif";
    for (const mark of this.marks) this.drawMark(mark, toScreen);
    this.drawLabels(toScreen);
    return busy;
  }

  /** The zones' names and counts, over the robots, with a halo. @param {(at: Point) => Point} toScreen */
  drawLabels(toScreen) {
    const context = this.context;
    context.lineJoin = "round";
    context.lineWidth = 4;
    context.strokeStyle = "rgba(255, 255, 255, 0.9)";
    for (const label of this.labels) {
      const below = toScreen(label.below), above = toScreen(label.above);
      context.font = "500 12px system-ui, sans-serif";
      context.fillStyle = this.colours.label || "#3d4a5c";
      context.strokeText(label.name, below.x, below.y + 9);
      context.fillText(label.name, below.x, below.y + 9);
      if (label.incoming) {
        context.font = "700 12px system-ui, sans-serif";
        context.fillStyle = this.colours.navigating;
        context.strokeText(label.incoming, above.x, above.y - 9);
        context.fillText(label.incoming, above.x, above.y - 9);
      }
    }
  }

  /** @param {Cluster} mark @param {(at: Point) => Point} toScreen */
  drawMark(mark, toScreen) {
    const context = this.context;
    const colour = this.colours[mark.status] || this.colours.idle;
    const single = mark.things.length === 1;
    const thing = mark.things[0];
    const radius = single ? DOT_PX : Math.min(CELL_PX / 2 - 1, CROWD_PX + 1.5 * Math.log10(mark.things.length));
    const trouble = mark.things.find((t) => this.troubled.has(t));
    if (single && thing === this.selected) {
      // The selected robot's way ahead: through the corners of its planned path, if any.
      const motion = this.robots.get(thing)?.motion;
      const ahead = motion ? motion.remaining(performance.now()) : [];
      if (ahead.length) {
        context.strokeStyle = colour;
        context.lineWidth = 1.5;
        context.setLineDash([4, 3]);
        context.beginPath();
        context.moveTo(mark.x, mark.y);
        for (const point of ahead) {
          const to = toScreen(point);
          context.lineTo(to.x, to.y);
        }
        context.stroke();
        context.setLineDash([]);
      }
    }
    context.beginPath();
    context.arc(mark.x, mark.y, radius, 0, 2 * Math.PI);
    context.fillStyle = colour;
    context.fill();
    if (trouble) {
      context.strokeStyle = this.colours[this.troubled.get(trouble) || "error"] || this.colours.error;
      context.lineWidth = 2;
      context.beginPath();
      context.arc(mark.x, mark.y, radius + 3, 0, 2 * Math.PI);
      context.stroke();
    }
    if (single && thing === this.selected) {
      context.strokeStyle = this.colours.select;
      context.lineWidth = 2.5;
      context.beginPath();
      context.arc(mark.x, mark.y, radius + 4, 0, 2 * Math.PI);
      context.stroke();
    }
    if (single && this.robots.get(thing)?.cargo) {
      context.fillStyle = this.colours.cargo;
      context.fillRect(mark.x + radius - 1, mark.y - radius - 3, 4, 4);
    }
    if (!single) {
      context.fillStyle = "#ffffff";
      context.fillText(String(mark.things.length), mark.x, mark.y + 0.5);
    }
  }
}
