// Finding robots by name, status and zone (vahr/station/static/search.js). Run by
// `make jstest` (node --test).

import assert from "node:assert/strict";
import { test } from "node:test";

import { findRobots, normalise } from "../../vahr/station/static/search.js";

const fleet = Array.from({ length: 300 }, (_, i) => ({
  thing: `rover${String(i + 1).padStart(4, "0")}`,
  name: `rover ${i + 1}`,
  status: i % 10 === 0 ? "stuck" : "idle",
  zone: i % 3 === 0 ? "A" : null,
}));
const placebots = [
  { thing: "placebot1", name: "placebot one", status: "idle", zone: "A" },
  { thing: "placebot2", name: "placebot two", status: "navigating", zone: null },
];

test("a whole spoken name comes first, then names that start with it, in fleet order", () => {
  const found = findRobots(fleet, { text: "Rover  17" });
  assert.deepEqual(found, ["rover0017", "rover0170", "rover0171", "rover0172", "rover0173", "rover0174", "rover0175", "rover0176", "rover0177", "rover0178", "rover0179"]);
});

test("words inside a name find it too, after the names that start with them", () => {
  assert.deepEqual(findRobots(placebots, { text: "bot" }), ["placebot1", "placebot2"]);
  assert.deepEqual(findRobots(fleet, { text: "r 29" }).slice(0, 2), ["rover0029", "rover0290"]);
});

test("a thing name finds its robot, with or without its spacing", () => {
  assert.deepEqual(findRobots(fleet, { text: "rover0042" }), ["rover0042"]);
  assert.deepEqual(findRobots(placebots, { text: "placebot 2" }), ["placebot2"]);
  assert.deepEqual(findRobots(placebots, { text: "TWO" }), ["placebot2"]);
});

test("status and zone narrow the results, with or without words", () => {
  const stuck = findRobots(fleet, { text: "", status: "stuck" });
  assert.equal(stuck.length, 30);
  const stuckInA = findRobots(fleet, { text: "", status: "stuck", zone: "A" });
  assert.deepEqual(stuckInA, ["rover0001", "rover0031", "rover0061", "rover0091", "rover0121", "rover0151", "rover0181", "rover0211", "rover0241", "rover0271"]);
  assert.deepEqual(findRobots(fleet, { text: "rover 2", status: "stuck", zone: "A" }), ["rover0211", "rover0241", "rover0271"]);
});

test("nothing typed and no filter: every robot, in order; nothing matching: none", () => {
  assert.equal(findRobots(fleet, { text: "  " }).length, 300);
  assert.deepEqual(findRobots(fleet, { text: "forklift" }), []);
  assert.deepEqual(findRobots(placebots, { text: "", zone: "D" }), []);
});

test("names are compared lower-cased and single-spaced", () => {
  assert.equal(normalise("  Rover\t 17 "), "rover 17");
});
