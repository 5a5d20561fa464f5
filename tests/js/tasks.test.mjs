// The fleet's task queue as the station lists it (vahr/station/static/tasks.js). Run by
// `make jstest` (node --test).

import assert from "node:assert/strict";
import { test } from "node:test";

import { ENDED_SHOWN, ordinal, taskLines } from "../../vahr/station/static/tasks.js";

const names = { placebot1: "placebot one", placebot2: "placebot two" };
const nameOf = (thing) => names[thing] || thing;
const zoneOf = (zone) => `zone ${zone}`;
const task = (id, status, minute, extra = {}) => ({ id, kind: "deliver", zone: "C", status, thing: null, created_at: `2026-11-26T23:${String(minute).padStart(2, "0")}:00Z`, ...extra });

test("the line comes first, oldest first, then who is doing what, then what ended", () => {
  const lines = taskLines([
    task("t4", "done", 1, { thing: "placebot2" }),
    task("t3", "queued", 9, { zone: "B" }),
    task("t2", "assigned", 5, { thing: "placebot1", kind: "navigate", zone: "D" }),
    task("t1", "queued", 7),
    task("t5", "cancelled", 2),
  ], nameOf, zoneOf);
  assert.deepEqual(lines.map((l) => [l.id, l.what, l.who]), [
    ["t1", "deliver to zone C", "first in line"],
    ["t3", "deliver to zone B", "2nd in line"],
    ["t2", "navigate to zone D", "placebot one"],
    ["t5", "deliver to zone C", "cancelled"],
    ["t4", "deliver to zone C", "done by placebot two"],
  ]);
});

test("only the latest ended tasks are listed", () => {
  const ended = Array.from({ length: 12 }, (_, i) => task(`d${i}`, "done", i, { thing: "placebot1" }));
  const lines = taskLines(ended, nameOf, zoneOf);
  assert.equal(lines.length, ENDED_SHOWN);
  assert.equal(lines[0].id, "d11");
});

test("an empty queue lists nothing", () => {
  assert.deepEqual(taskLines([], nameOf, zoneOf), []);
});

test("ordinals", () => {
  assert.deepEqual([1, 2, 3, 4, 11, 12, 13, 21, 22, 101].map(ordinal), ["1st", "2nd", "3rd", "4th", "11th", "12th", "13th", "21st", "22nd", "101st"]);
});
