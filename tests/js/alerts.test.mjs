// The station's alerts (vahr/station/static/alerts.js): which announcements the page shows,
// in which order, once each, until acknowledged. Run by `make jstest` (node --test).

import assert from "node:assert/strict";
import { describe, test } from "node:test";

import { AlertQueue, BEEP_GAP_MS, IDS_PER_ALERT, REMEMBERED } from "../../vahr/station/static/alerts.js";

const T0 = Date.parse("2026-11-23T10:00:00Z");
const PRIORITIES = { stuck: 3, offline: 3, failed: 2, waiting: 1, done: 0 };

// An announcement as the station sends it, `seconds` after T0.
function announced(id, thing, kind, seconds = 0, speech = `${thing} ${kind}`) {
  const time = new Date(T0 + seconds * 1000).toISOString();
  return { type: "announcement", id, time, opened_at: time, thing, kind, priority: PRIORITIES[kind], speech, reason: null, person: "everyone", robots: thing ? [thing] : [] };
}

const shown = (queue) => queue.list().map((alert) => [alert.key, alert.ids]);

describe("what is shown", () => {
  test("each announcement shows as an alert naming its robot and trouble", () => {
    const queue = new AlertQueue();
    const alert = queue.add(announced("a1", "placebot1", "stuck"));
    assert.equal(alert.key, "placebot1 stuck");
    assert.equal(alert.latest.speech, "placebot1 stuck");
    assert.deepEqual(shown(queue), [["placebot1 stuck", ["a1"]]]);
  });

  test("the same announcement twice (a redelivery, a new snapshot) shows once", () => {
    const queue = new AlertQueue();
    assert.ok(queue.add(announced("a1", "placebot1", "stuck")));
    assert.equal(queue.add(announced("a1", "placebot1", "stuck")), null);
    assert.equal(queue.reset([announced("a1", "placebot1", "stuck")]), 0);
    assert.deepEqual(shown(queue), [["placebot1 stuck", ["a1"]]]);
  });

  test("the same trouble of the same robot again joins its open alert, with the newer words", () => {
    const queue = new AlertQueue();
    queue.add(announced("a1", "placebot1", "stuck", 0, "first"));
    queue.add(announced("a2", "placebot1", "failed", 1));
    const joined = queue.add(announced("a3", "placebot1", "stuck", 2, "again"));
    assert.deepEqual(joined.ids, ["a1", "a3"]);
    assert.equal(joined.latest.speech, "again");
    assert.deepEqual(shown(queue), [["placebot1 stuck", ["a1", "a3"]], ["placebot1 failed", ["a2"]]]);
  });

  test("the most urgent first, then the oldest", () => {
    const queue = new AlertQueue();
    queue.add(announced("w", "placebot2", "waiting", 0));
    queue.add(announced("f", "placebot1", "failed", 1));
    queue.add(announced("o", "placebot2", "offline", 3));
    queue.add(announced("s", "placebot1", "stuck", 2));
    assert.deepEqual(queue.list().map((a) => a.ids[0]), ["s", "o", "f", "w"]);
  });

  test("the map rings each robot for its most urgent open trouble", () => {
    const queue = new AlertQueue();
    queue.add(announced("f", "placebot1", "failed", 0));
    queue.add(announced("s", "placebot1", "stuck", 1));
    queue.add(announced("w", null, "waiting", 2));
    assert.deepEqual([...queue.troubled()], [["placebot1", "stuck"]]);
  });
});

describe("acknowledging", () => {
  test("acknowledging an alert lets go of every announcement it stood for", () => {
    const queue = new AlertQueue();
    queue.add(announced("a1", "placebot1", "stuck"));
    queue.add(announced("a2", "placebot1", "stuck", 5));
    queue.add(announced("b1", "placebot2", "offline"));
    assert.deepEqual(queue.acknowledge("placebot1 stuck"), ["a1", "a2"]);
    assert.deepEqual(shown(queue), [["placebot2 offline", ["b1"]]]);
    assert.deepEqual(queue.acknowledge("placebot1 stuck"), []); // twice: nothing more
  });

  test("a new fault after the acknowledgment is a new alert", () => {
    const queue = new AlertQueue();
    queue.add(announced("a1", "placebot1", "stuck"));
    queue.acknowledge("placebot1 stuck");
    assert.ok(queue.add(announced("a2", "placebot1", "stuck", 60)));
    assert.deepEqual(shown(queue), [["placebot1 stuck", ["a2"]]]);
  });

  test("an acknowledgment from another page lets the alert go here", () => {
    const queue = new AlertQueue();
    queue.add(announced("a1", "placebot1", "stuck"));
    queue.add(announced("b1", "placebot2", "stuck"));
    assert.equal(queue.acknowledged(["a1"]), true);
    assert.equal(queue.acknowledged(["a1", "zz"]), false);
    assert.deepEqual(shown(queue), [["placebot2 stuck", ["b1"]]]);
  });

  test("an acknowledgment heard before its announcement keeps it from showing", () => {
    const queue = new AlertQueue();
    queue.acknowledged(["a1"]);
    assert.equal(queue.add(announced("a1", "placebot1", "stuck")), null);
    assert.deepEqual(shown(queue), []);
  });

  test("a snapshot shows what is open at the station: news added, the acknowledged gone", () => {
    const queue = new AlertQueue();
    queue.add(announced("a1", "placebot1", "stuck"));
    queue.add(announced("b1", "placebot2", "offline"));
    queue.acknowledge("placebot2 offline"); // here, before the station heard of it
    const fresh = queue.reset([announced("b1", "placebot2", "offline"), announced("c1", "placebot2", "failed", 9)]);
    assert.equal(fresh, 1);
    assert.deepEqual(shown(queue), [["placebot2 failed", ["c1"]]]);
  });

  test("an alert without a robot (a task kept waiting) is acknowledged alone", () => {
    const queue = new AlertQueue();
    queue.add(announced("q1", null, "waiting"));
    queue.add(announced("q2", null, "waiting", 1));
    assert.deepEqual(queue.acknowledge("q1"), ["q1"]);
    assert.deepEqual(shown(queue), [["q2", ["q2"]]]);
  });
});

describe("beeps and memory", () => {
  test("a burst of alerts beeps once", () => {
    const clock = { ms: T0 };
    const queue = new AlertQueue({ now: () => clock.ms });
    assert.equal(queue.beep(), true);
    clock.ms += BEEP_GAP_MS - 1;
    assert.equal(queue.beep(), false);
    clock.ms += 1;
    assert.equal(queue.beep(), true);
  });

  test("the ids remembered are bounded", () => {
    const queue = new AlertQueue();
    for (let i = 0; i < REMEMBERED + 10; i += 1) queue.add(announced(`a${i}`, "placebot1", "stuck", i));
    assert.equal(queue.seen.size, REMEMBERED);
    const [alert] = queue.list();
    assert.equal(alert.count, REMEMBERED + 10);
    assert.equal(alert.ids.length, IDS_PER_ALERT);
    queue.acknowledged(Array.from({ length: REMEMBERED + 5 }, (_, i) => `other${i}`));
    assert.equal(queue.acknowledgedIds.size, REMEMBERED);
  });
});
