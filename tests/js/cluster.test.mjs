// Robots crowding on the map drawn as one mark (vahr/station/static/cluster.js). Run by
// `make jstest` (node --test).

import assert from "node:assert/strict";
import { test } from "node:test";

import { cluster, hit } from "../../vahr/station/static/cluster.js";

const at = (thing, x, y, status = "idle") => ({ thing, x, y, status });

test("robots in one square are one mark at their mean, apart ones stay single", () => {
  const marks = cluster([at("a", 1, 1), at("b", 5, 9), at("c", 30, 30)], 16);
  assert.equal(marks.length, 2);
  assert.deepEqual(marks[0], { x: 3, y: 5, things: ["a", "b"], status: "idle" });
  assert.deepEqual(marks[1].things, ["c"]);
});

test("a crowd shows its most pressing status, whatever the order", () => {
  const crowd = [at("a", 1, 1, "navigating"), at("b", 2, 2, "stuck"), at("c", 3, 3, "offline"), at("d", 4, 4)];
  assert.equal(cluster(crowd, 16)[0].status, "stuck");
  assert.equal(cluster(crowd.reverse(), 16)[0].status, "stuck");
  assert.equal(cluster([at("a", 1, 1, "error"), at("b", 1, 1, "stuck")], 16)[0].status, "error");
});

test("the selected robot is drawn apart from its crowd, last (on top)", () => {
  const marks = cluster([at("a", 1, 1), at("b", 2, 2), at("c", 3, 3)], 16, "b");
  assert.deepEqual(marks.map((m) => m.things), [["a", "c"], ["b"]]);
});

test("every robot is in exactly one mark, however many", () => {
  const many = Array.from({ length: 10_000 }, (_, i) => at(`r${i}`, (i * 7919) % 1280, (i * 104729) % 800));
  const marks = cluster(many, 12);
  const things = marks.flatMap((m) => m.things);
  assert.equal(things.length, 10_000);
  assert.equal(new Set(things).size, 10_000);
  assert.ok(marks.length < 10_000);
});

test("a click selects the nearest mark within reach, or nothing", () => {
  const marks = cluster([at("a", 10, 10), at("b", 60, 10)], 16);
  assert.deepEqual(hit(marks, 14, 12, 10)?.things, ["a"]);
  assert.deepEqual(hit(marks, 55, 10, 10)?.things, ["b"]);
  assert.equal(hit(marks, 35, 10, 10), null);
});
