// Which rows of a long list have elements (vahr/station/static/virtual-list.js). Run by
// `make jstest` (node --test).

import assert from "node:assert/strict";
import { test } from "node:test";

import { rowsInView, scrollToShow } from "../../vahr/station/static/virtual-list.js";

test("the rows in view and a few on each side, never past the ends", () => {
  assert.deepEqual(rowsInView(0, 300, 30, 1000, 4), { first: 0, last: 14 });
  assert.deepEqual(rowsInView(3000, 300, 30, 1000, 4), { first: 96, last: 114 });
  assert.deepEqual(rowsInView(29_700, 300, 30, 1000, 4), { first: 986, last: 1000 });
});

test("however long the list, the rows drawn stay a screenful", () => {
  for (const count of [10, 1000, 10_000]) {
    const { first, last } = rowsInView(15 * count, 300, 30, count);
    assert.ok(last - first <= 300 / 30 + 9, `${count}: ${last - first} rows`);
  }
});

test("an empty list has no rows", () => {
  assert.deepEqual(rowsInView(0, 300, 30, 0), { first: 0, last: 0 });
});

test("showing a row scrolls as little as needed", () => {
  assert.equal(scrollToShow(5, 0, 300, 30), 0); // already in view
  assert.equal(scrollToShow(50, 0, 300, 30), 50 * 30 + 30 - 300); // below: at the bottom
  assert.equal(scrollToShow(2, 600, 300, 30), 60); // above: at the top
});
