// The station's words per locale: which language the page shows, and that both word lists
// name the same places on the page, each of which the page has.
import assert from "node:assert/strict";
import { readFileSync } from "node:fs";
import { test } from "node:test";

import { chooseLocale, SUPPORTED } from "../../vahr/station/static/i18n.js";

const LOCALES = new URL("../../vahr/station/locales/", import.meta.url);
// The station's pages: the station itself, and the sign-in page of a station people sign in to.
const PAGE = ["index.html", "signin.html"]
  .map((page) => readFileSync(new URL(`../../vahr/station/static/${page}`, import.meta.url), "utf8"))
  .join("\n");
const words = (locale) => JSON.parse(readFileSync(new URL(`${locale}.json`, LOCALES), "utf8"));

test("a German browser gets German, an Austrian one too, anything else English", () => {
  assert.equal(chooseLocale(null, ["de-DE", "en-US"]), "de-DE");
  assert.equal(chooseLocale(null, ["de-AT"]), "de-DE");
  assert.equal(chooseLocale(null, ["fr-FR", "en-GB"]), "en-US");
  assert.equal(chooseLocale(null, ["fr-FR"]), "en-US");
});

test("a language chosen in the selector wins over the browser's", () => {
  assert.equal(chooseLocale("en-US", ["de-DE"]), "en-US");
  assert.equal(chooseLocale("xx-XX", ["de-DE"]), "de-DE");
});

test("every locale words the same places of the page", () => {
  const english = words("en-US");
  for (const locale of SUPPORTED) {
    const other = words(locale);
    for (const part of ["text", "html", "after", "attr"]) {
      assert.deepEqual(Object.keys(other[part]).sort(), Object.keys(english[part]).sort(), `${locale} ${part}`);
    }
  }
});

test("the English words are the page's own", () => {
  const english = words("en-US");
  for (const text of [...Object.values(english.text), ...Object.values(english.after)]) {
    assert.ok(PAGE.includes(text.replace("'", "&#39;")) || PAGE.includes(text), text);
  }
  for (const attributes of Object.values(english.attr)) {
    for (const value of Object.values(attributes)) assert.ok(PAGE.includes(`"${value}"`), value);
  }
});

// What the scripts write (`t`, `tNodes`) and say to the assistant (`said`), by their English
// wording: each in every other locale, with the same placeholders.
const STATIC = new URL("../../vahr/station/static/", import.meta.url);
const scripts = ["alerts-view", "conversation", "map", "panel", "robots", "station", "talk", "tasks", "tasks-view", "trail-view", "zones-view"]
  .map((name) => readFileSync(new URL(`${name}.js`, STATIC), "utf8"));
const used = (pattern) => new Set(scripts.flatMap((text) => [...text.matchAll(pattern)].map((m) => m[1])));
const placeholders = (text) => [...text.matchAll(/\{(\w+)\}/g)].map((m) => m[1]).sort();

test("every sentence the scripts write is in every locale, with its placeholders", () => {
  const strings = used(/\b(?:t|tr|tNodes)\("((?:[^"\\]|\\.)*)"/g);
  assert.ok(strings.size > 100, "the scripts' sentences were found");
  for (const locale of SUPPORTED.filter((code) => code !== "en-US")) {
    const table = words(locale).strings;
    for (const english of strings) {
      assert.ok(english in table, `${locale} lacks "${english}"`);
      assert.deepEqual(placeholders(table[english]), placeholders(english), english);
    }
  }
});

test("what the page says to the assistant is in the assistant's every language", () => {
  const utterances = used(/\bsaid\("((?:[^"\\]|\\.)*)"/g);
  assert.ok(utterances.size >= 2);
  for (const locale of SUPPORTED.filter((code) => code !== "en-US")) {
    for (const english of utterances) assert.ok(english in words(locale).utterances, `${locale} lacks "${english}"`);
  }
});
