// A robot's change applied on the page (vahr/station/static/changes.js): only what changed
// arrives, and the page must end where the station is. Run by `make jstest` (node --test).

import assert from "node:assert/strict";
import { test } from "node:test";

import { applyChange } from "../../vahr/station/static/changes.js";

function robot() {
  return { reported: { status: "idle", zone: "A", cargo: false, task: "deliver" }, version: 1, online: true, last_seen: 10, last_event: null, progress: null };
}

test("changed fields are merged, removed ones dropped, the rest kept", () => {
  const shown = robot();
  applyChange(shown, { thing: "r1", reported: { status: "navigating", destination: "B" }, removed: ["task"], version: 2 });
  assert.deepEqual(shown.reported, { status: "navigating", zone: "A", cargo: false, destination: "B" });
  assert.equal(shown.version, 2);
  assert.equal(shown.online, true);
  assert.equal(shown.last_seen, 10);
});

test("presence alone leaves the reported state as it was", () => {
  const shown = robot();
  const before = shown.reported;
  applyChange(shown, { thing: "r1", online: false, last_seen: 99 });
  assert.equal(shown.reported, before);
  assert.equal(shown.online, false);
  assert.equal(shown.last_seen, 99);
});

test("the latest event is kept, and progress is the drive's state after it", () => {
  const shown = robot();
  const progress = { event: "progress", thing: "r1", progress: 0.4, pose: { x: 1, y: 2, theta: 0 } };
  const accepted = { event: "accepted", thing: "r1" };
  applyChange(shown, { thing: "r1", last_event: accepted, progress });
  assert.equal(shown.progress, progress);
  assert.equal(shown.last_event, accepted);
  const arrived = { event: "arrived", thing: "r1", zone: "B" };
  applyChange(shown, { thing: "r1", last_event: arrived, progress: null });
  assert.equal(shown.progress, null);
  assert.equal(shown.last_event, arrived);
  // A change without either leaves both
  applyChange(shown, { thing: "r1", online: true });
  assert.equal(shown.last_event, arrived);
});
