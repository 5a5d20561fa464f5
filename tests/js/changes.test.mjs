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

test("progress is the drive's, and null ends it", () => {
  const shown = robot();
  const progress = { event: "progress", thing: "r1", progress: 0.4, pose: { x: 1, y: 2, theta: 0 } };
  applyChange(shown, { thing: "r1", progress });
  assert.equal(shown.progress, progress);
  assert.equal(shown.last_event, progress);
  applyChange(shown, { thing: "r1", progress: null });
  assert.equal(shown.progress, null);
  assert.equal(shown.last_event, progress);
});
