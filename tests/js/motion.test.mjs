// The map's motion (vahr/station/static/motion.js): how a robot is drawn between the poses
// it reports. Run by `make jstest` (node --test).

import assert from "node:assert/strict";
import { describe, test } from "node:test";

import { DEFAULT_SPEED, EASE_MS, Motion, TURN_RATE, distance } from "../../vahr/station/static/motion.js";

// A clock the test moves by hand, in milliseconds.
function manualClock(start = 1000) {
  const clock = { ms: start, now: () => clock.ms };
  return clock;
}

function near(actual, expected, tolerance = 1e-9) {
  assert.ok(distance(actual, expected) <= tolerance, `drawn at (${actual.x}, ${actual.y}), expected (${expected.x}, ${expected.y})`);
}

describe("a robot moving between poses", () => {
  test("moves from its reported pose toward its destination at the default speed", () => {
    const clock = manualClock();
    const motion = new Motion({ x: 0, y: 0, theta: 0 }, clock.now);
    motion.report({ x: 0, y: 0 }, { x: 4, y: 0 });
    clock.ms += 2000;
    near(motion.position(clock.ms), { x: 2 * DEFAULT_SPEED, y: 0 });
    assert.equal(motion.driving, true);
  });

  test("takes up the speed its reports imply", () => {
    const clock = manualClock();
    const motion = new Motion({ x: 0, y: 0 }, clock.now);
    const target = { x: 10, y: 0 };
    motion.report({ x: 0, y: 0 }, target);
    // Given two reports a second apart, 2 m apart (2 m/s)
    clock.ms += 1000;
    motion.report({ x: 2, y: 0 }, target);
    // Then the speed believed is halfway from the old one to the one measured
    assert.equal(motion.speed, 0.5 * DEFAULT_SPEED + 0.5 * 2);
    clock.ms += EASE_MS; // the report agreed more or less: past its easing, it moves at that speed
    const before = motion.position(clock.ms);
    near(motion.position(clock.ms + 1000), { x: before.x + motion.speed, y: 0 });
  });

  test("turns toward the way it drives no faster than its turn rate", () => {
    const clock = manualClock();
    const motion = new Motion({ x: 0, y: 0, theta: 0 }, clock.now);
    motion.report({ x: 0, y: 0 }, { x: 0, y: 5 });
    const heading = motion.headingAt(clock.ms, 0.1);
    assert.equal(heading, TURN_RATE * 0.1);
    for (let step = 0; step < 10; step += 1) motion.headingAt(clock.ms, 0.1);
    assert.equal(motion.heading, Math.PI / 2);
  });
});

describe("arrival", () => {
  test("stops at the destination and never overshoots it", () => {
    const clock = manualClock();
    const motion = new Motion({ x: 0, y: 0 }, clock.now);
    motion.report({ x: 0, y: 0 }, { x: 1, y: 1 });
    clock.ms += 60_000;
    near(motion.position(clock.ms), { x: 1, y: 1 });
    assert.equal(motion.driving, false);
  });

  test("eases into the arrival pose from where the robot was drawn, without a jump", () => {
    const clock = manualClock();
    const motion = new Motion({ x: 0, y: 0 }, clock.now);
    motion.report({ x: 0, y: 0 }, { x: 4, y: 0 });
    clock.ms += 1000; // drawn at x = 0.5
    const drawn = motion.position(clock.ms);
    // When the robot reports it arrived elsewhere (no target any more)
    motion.report({ x: 1.5, y: 0.2, theta: 1 }, null);
    // Then it is drawn where it was at that moment, and at the reported pose once eased
    near(motion.position(clock.ms), drawn);
    const halfway = motion.position(clock.ms + EASE_MS / 2);
    assert.ok(halfway.x > drawn.x && halfway.x < 1.5);
    near(motion.position(clock.ms + EASE_MS), { x: 1.5, y: 0.2 });
    assert.equal(motion.theta, 1);
    assert.equal(motion.driving, false);
  });
});

describe("a new target mid-way", () => {
  test("turns to the new destination from where the robot is drawn", () => {
    const clock = manualClock();
    const motion = new Motion({ x: 0, y: 0 }, clock.now);
    motion.report({ x: 0, y: 0 }, { x: 4, y: 0 });
    clock.ms += 2000; // drawn at x = 1
    const drawn = motion.position(clock.ms);
    // When a new command sends it up instead, reported where it was drawn
    motion.report({ x: 1, y: 0 }, { x: 1, y: 3 });
    near(motion.position(clock.ms), drawn);
    // Then it heads for the new target, not the old one
    clock.ms += 2000;
    near(motion.position(clock.ms), { x: 1, y: 2 * DEFAULT_SPEED });
    assert.deepEqual(motion.target, { x: 1, y: 3 });
    assert.equal(motion.last?.target.y, 3);
  });

  test("does not take the jump to a new target's first report as speed", () => {
    const clock = manualClock();
    const motion = new Motion({ x: 0, y: 0 }, clock.now);
    motion.report({ x: 0, y: 0 }, { x: 4, y: 0 });
    clock.ms += 1000;
    motion.report({ x: 3, y: 0 }, { x: 0, y: 4 });
    assert.equal(motion.speed, DEFAULT_SPEED);
  });
});

describe("stale updates", () => {
  test("a report behind where the robot is drawn holds the drawn place, never backs up", () => {
    const clock = manualClock();
    const motion = new Motion({ x: 0, y: 0 }, clock.now);
    const target = { x: 10, y: 0 };
    motion.report({ x: 0, y: 0 }, target);
    clock.ms += 4000; // drawn at x = 2
    const drawn = motion.position(clock.ms);
    // When a late report says the robot was still at x = 1
    motion.report({ x: 1, y: 0 }, target);
    // Then the robot stays where it was drawn and keeps going forward from there
    near(motion.position(clock.ms), drawn);
    let previous = drawn.x;
    for (let t = clock.ms; t <= clock.ms + 3000; t += 100) {
      const at = motion.position(t);
      assert.ok(at.x >= previous - 1e-9, `slid back from ${previous} to ${at.x} at ${t}`);
      previous = at.x;
    }
  });

  test("the same report again changes nothing", () => {
    const clock = manualClock();
    const motion = new Motion({ x: 0, y: 0 }, clock.now);
    const target = { x: 10, y: 0 };
    motion.report({ x: 0, y: 0 }, target);
    clock.ms += 1000;
    motion.report({ x: 0.5, y: 0 }, target);
    const speed = motion.speed;
    const drawn = motion.position(clock.ms + 500);
    motion.report({ x: 0.5, y: 0 }, target); // a duplicate, at the same moment
    assert.equal(motion.speed, speed);
    near(motion.position(clock.ms + 500), drawn);
  });
});

describe("a robot driving a planned path", () => {
  test("is drawn along the path's legs, round the corner, never across it", () => {
    const clock = manualClock();
    const motion = new Motion({ x: 0, y: 0 }, clock.now);
    // Given a path from (0, 0) up to (0, 2), then across to (2, 2), the goal
    const route = [{ x: 0, y: 0 }, { x: 0, y: 2 }, { x: 2, y: 2 }];
    motion.report({ x: 0, y: 0 }, { x: 2, y: 2 }, route);
    // When three seconds pass at the default speed (1.5 m)
    clock.ms += 3000;
    // Then it is drawn on the first leg, not on the straight line to the goal
    near(motion.position(clock.ms), { x: 0, y: 3 * DEFAULT_SPEED });
    // And five seconds later (4 m in all, the path's length) at the goal, having turned the corner
    clock.ms += 5000;
    near(motion.position(clock.ms), { x: 2, y: 2 });
    assert.deepEqual(motion.remaining(clock.ms), [{ x: 2, y: 2 }]);
  });

  test("a report half way along the second leg leaves only the rest ahead", () => {
    const clock = manualClock();
    const motion = new Motion({ x: 0, y: 0 }, clock.now);
    const route = [{ x: 0, y: 0 }, { x: 0, y: 2 }, { x: 2, y: 2 }];
    motion.report({ x: 0, y: 0 }, { x: 2, y: 2 }, route);
    clock.ms += 6000; // drawn at (1, 2) at the default speed
    motion.report({ x: 1, y: 2 }, { x: 2, y: 2 }, route);
    assert.deepEqual(motion.remaining(clock.ms).at(-1), { x: 2, y: 2 });
    assert.ok(motion.remaining(clock.ms).every((point) => point.y === 2), "nothing behind it is ahead");
  });
});
