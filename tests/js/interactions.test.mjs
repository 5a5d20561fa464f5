// The participant's interaction time (vahr/station/static/interactions.js): what the page
// sends to the session's log when a click, key press or push-to-talk starts and ends. Run
// by `make jstest` (node --test).

import assert from "node:assert/strict";
import { describe, test } from "node:test";

import { Interactions, REACH_MS, SETTLE_MS, STILL_MS } from "../../vahr/station/static/interactions.js";

const T0 = Date.parse("2026-11-23T10:00:00Z");
const iso = (ms) => new Date(ms).toISOString();

// Interactions on a hand-moved clock, sending into a list, with no real waiting.
function recorder({ session = "P01-keyboard-trial1" } = {}) {
  const sent = [];
  const clock = { ms: T0 };
  const waits = [];
  const interactions = new Interactions({
    send: (body) => sent.push(body),
    now: () => clock.ms,
    wait: (ms) => { waits.push(ms); return Promise.resolve(); },
    prefix: "page",
  });
  interactions.setSession(session);
  return { interactions, sent, clock, waits };
}

describe("start and stop", () => {
  test("a key press is sent when it starts and when it ends, with both times", async () => {
    const { interactions, sent, clock } = recorder();
    interactions.keyDown("KeyB", "b");
    clock.ms += 150;
    interactions.keyUp("KeyB");
    await settled(interactions);
    assert.deepEqual(sent, [
      { id: "page-1", phase: "started", channel: "key", at: iso(T0), text: "key b", sent: iso(T0) },
      { id: "page-1", phase: "ended", channel: "key", at: iso(T0 + 150), text: "key b", commands: [], counts: false, asks: false, sent: iso(T0 + 150) },
    ]);
  });

  test("what an interaction caused goes with its end", async () => {
    const { interactions, sent } = recorder();
    const click = interactions.start("click", "click zone B", T0);
    interactions.attach(Promise.resolve({ commands: ["c1"] }));
    interactions.attach(Promise.resolve({ asks: true, speech: "It is sunny.", intent: "WeatherIntent" }));
    interactions.attach(Promise.resolve({ error: "The station does not answer" }));
    await interactions.end(click, T0 + 900);
    const ended = sent.at(-1);
    assert.deepEqual(
      [ended.commands, ended.counts, ended.asks, ended.speech, ended.intent, ended.error],
      [["c1"], true, true, "It is sunny.", "WeatherIntent", "The station does not answer"],
    );
  });

  test("an interaction that sent nothing does not count as communication", async () => {
    const { interactions, sent } = recorder();
    const click = interactions.start("click", "click robot placebot1", T0);
    interactions.attach(Promise.resolve(null)); // selecting a robot sends nothing
    await interactions.end(click, T0 + 300);
    assert.equal(sent.at(-1).counts, false);
  });

  test("a key that acknowledged an alert ends saying so", async () => {
    const { interactions, sent, clock } = recorder();
    interactions.keyDown("Enter", "Enter");
    interactions.attach(Promise.resolve({ text: "acknowledge alert placebot1 stuck" }));
    clock.ms += 120;
    interactions.keyUp("Enter");
    await settled(interactions);
    assert.deepEqual(sent.map((m) => [m.phase, m.text]), [["started", "key Enter"], ["ended", "acknowledge alert placebot1 stuck"]]);
    assert.equal(sent.at(-1).counts, false); // interaction time, not an order to a robot
  });

  test("a click's action that starts just after the release still belongs to it", async () => {
    const { interactions, sent, waits } = recorder();
    interactions.pointerDown({ mouse: false, text: "click Stop all" });
    interactions.pointerUp();
    // The release waits SETTLE_MS before it gives up the click as the active interaction
    assert.deepEqual(waits, [SETTLE_MS]);
    interactions.attach(Promise.resolve({ commands: ["stop-1"] }));
    await settled(interactions);
    assert.deepEqual(sent.at(-1).commands, ["stop-1"]);
  });

  test("ending twice sends one end; without a session nothing is sent", async () => {
    const { interactions, sent } = recorder();
    const key = interactions.start("key", "key Escape", T0);
    await interactions.end(key, T0 + 10);
    await interactions.end(key, T0 + 20);
    assert.deepEqual(sent.map((body) => body.phase), ["started", "ended"]);

    const alone = recorder({ session: null });
    await alone.interactions.end(alone.interactions.start("key", "key a", T0), T0 + 5);
    assert.deepEqual(alone.sent, []);
  });
});

describe("overlapping interactions", () => {
  test("a key held while clicking: each ends with its own times and its own outcome", async () => {
    const { interactions, sent, clock } = recorder();
    interactions.keyDown("Digit1", "1");
    clock.ms += 100;
    interactions.pointerDown({ mouse: false, text: "click zone C" });
    interactions.attach(Promise.resolve({ commands: ["nav-1"] })); // the click sent a navigation
    clock.ms += 200;
    interactions.keyUp("Digit1");
    clock.ms += 100;
    interactions.pointerUp();
    await settled(interactions);
    const ends = Object.fromEntries(sent.filter((b) => b.phase === "ended").map((b) => [b.text, b]));
    assert.equal(ends["key 1"].at, iso(T0 + 300));
    assert.deepEqual(ends["key 1"].commands, []);
    assert.equal(ends["click zone C"].at, iso(T0 + 400));
    assert.deepEqual(ends["click zone C"].commands, ["nav-1"]);
    const started = sent.filter((b) => b.phase === "started");
    assert.deepEqual(started.map((b) => [b.id, b.at]), [["page-1", iso(T0)], ["page-2", iso(T0 + 100)]]);
  });

  test("a key already down is one interaction until it is up", async () => {
    const { interactions, sent, clock } = recorder();
    interactions.keyDown("KeyA", "a");
    clock.ms += 50;
    interactions.keyDown("KeyA", "a");
    clock.ms += 50;
    interactions.keyUp("KeyA");
    interactions.keyUp("KeyA");
    await settled(interactions);
    assert.deepEqual(sent.map((b) => [b.id, b.phase]), [["page-1", "started"], ["page-1", "ended"]]);
  });
});

describe("idle gaps", () => {
  test("a click starts with the pointer's movement towards it", () => {
    const { interactions, sent, clock } = recorder();
    for (let step = 0; step < 5; step += 1) { interactions.moved(); clock.ms += 100; }
    interactions.pointerDown({ mouse: true, text: "click zone A" });
    assert.equal(sent[0].at, iso(T0));
  });

  test("a pointer at rest longer than STILL_MS starts a new movement", () => {
    const { interactions, sent, clock } = recorder();
    interactions.moved(); // the last movement ends here...
    clock.ms += STILL_MS + 600; // ...then the participant reads the screen
    const reachStarts = clock.ms;
    interactions.moved();
    clock.ms += 300;
    interactions.moved();
    clock.ms += 200;
    interactions.pointerDown({ mouse: true, text: "click zone D" });
    assert.equal(sent[0].at, iso(reachStarts));
  });

  test("a movement longer ago than REACH_MS is not the reach for this click", () => {
    const { interactions, sent, clock } = recorder();
    interactions.moved();
    clock.ms += REACH_MS + 1;
    interactions.pointerDown({ mouse: true, text: "click zone B" });
    assert.equal(sent[0].at, iso(clock.ms));
  });

  test("a touch starts when the finger touches, whatever moved before", () => {
    const { interactions, sent, clock } = recorder();
    interactions.moved();
    clock.ms += 200;
    interactions.pointerDown({ mouse: false, text: "click zone B" });
    assert.equal(sent[0].at, iso(T0 + 200));
  });
});

// Let every pending end (each a chain of already-resolved promises) finish.
async function settled(interactions) {
  for (let turn = 0; turn < 10; turn += 1) await Promise.resolve();
  assert.equal(interactions.active, null);
}
