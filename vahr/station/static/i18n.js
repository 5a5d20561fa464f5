// @ts-check
// The station's words in the reader's language. Each locale's words are
// vahr/station/locales/<locale>.json (served as /static/<locale>.json): the page's text by
// CSS selector ("text", "html" for our own markup, "after" for the text right after an
// element, "attr" for attributes), and "strings", what the scripts write (`t`), by their
// English wording with `{name}` placeholders. The language is the one chosen in the page's
// selector (kept in localStorage), else the one people speak to the assistant (the
// station's `data-locale` on <html>, `vahr up --locale`), else the browser's first language
// VAHR speaks, else English. The page is written in English, so English needs nothing.
// This module waits for the words before any other is evaluated (a top-level await), so a
// script's `t()` is never English by accident.

export const SUPPORTED = ["en-US", "de-DE"];
export const DEFAULT_LOCALE = "en-US";
const STORAGE_KEY = "vahr.station.locale";

/**
 * The locale to show: a saved choice if VAHR speaks it, else the first of the browser's
 * languages VAHR speaks (by language: "de-AT" reads German), else English.
 * @param {string | null} saved
 * @param {readonly string[]} languages
 * @returns {string}
 */
export function chooseLocale(saved, languages) {
  if (saved && SUPPORTED.includes(saved)) return saved;
  for (const language of languages) {
    const exact = SUPPORTED.find((locale) => locale.toLowerCase() === language.toLowerCase());
    if (exact) return exact;
    const same = SUPPORTED.find((locale) => locale.split("-")[0] === language.toLowerCase().split("-")[0]);
    if (same) return same;
  }
  return DEFAULT_LOCALE;
}

/**
 * @typedef {object} Words
 * @property {string} lang
 * @property {string} name
 * @property {string} language_label
 * @property {Record<string, string>} text
 * @property {Record<string, string>} html
 * @property {Record<string, string>} after
 * @property {Record<string, Record<string, string>>} attr
 * @property {Record<string, string>} [strings]
 * @property {Record<string, string>} [utterances]
 */

/**
 * Put `words` on the page under `root`.
 * @param {ParentNode} root
 * @param {Words} words
 */
export function applyWords(root, words) {
  for (const [selector, text] of Object.entries(words.text)) {
    for (const element of root.querySelectorAll(selector)) element.textContent = text;
  }
  for (const [selector, html] of Object.entries(words.html)) {
    // Markup from the station's own word lists only (kbd, small, the stop icon).
    for (const element of root.querySelectorAll(selector)) element.innerHTML = html;
  }
  for (const [selector, text] of Object.entries(words.after)) {
    for (const element of root.querySelectorAll(selector)) {
      const next = element.nextSibling;
      if (next && next.nodeType === Node.TEXT_NODE) next.textContent = text;
    }
  }
  for (const [selector, attributes] of Object.entries(words.attr)) {
    for (const element of root.querySelectorAll(selector)) {
      for (const [name, value] of Object.entries(attributes)) element.setAttribute(name, value);
    }
  }
}

/**
 * The language selector in the top bar; choosing one keeps it and shows the page in it.
 * @param {string} current
 * @param {Record<string, string>} names locale -> the language's own name
 * @param {string} label
 */
function addSelector(current, names, label) {
  const bar = document.querySelector(".topbar");
  if (!bar) return;
  const wrapper = document.createElement("label");
  // The reply-voice selector's look.
  wrapper.className = "voice-choice language-choice";
  const caption = document.createElement("span");
  caption.textContent = label;
  const select = document.createElement("select");
  select.id = "page-language";
  for (const locale of SUPPORTED) {
    const option = document.createElement("option");
    option.value = locale;
    option.textContent = names[locale] ?? locale;
    option.selected = locale === current;
    select.append(option);
  }
  select.addEventListener("change", () => {
    localStorage.setItem(STORAGE_KEY, select.value);
    location.reload();
  });
  wrapper.append(caption, select);
  bar.append(wrapper);
}

/** @param {string} locale @returns {Promise<Words>} */
async function wordsOf(locale) {
  const answer = await fetch(`/static/${locale}.json`);
  if (!answer.ok) throw new Error(`the station has no words for ${locale}`);
  return /** @type {Words} */ (await answer.json());
}

const inBrowser = typeof document !== "undefined" && typeof window !== "undefined";

/** The locale the page shows (English outside a browser). */
export const LOCALE = inBrowser
  ? chooseLocale(localStorage.getItem(STORAGE_KEY), [
      ...(document.documentElement.dataset.locale ? [document.documentElement.dataset.locale] : []),
      ...(navigator.languages ?? [navigator.language]),
    ])
  : DEFAULT_LOCALE;

/** The language people speak to the assistant (`vahr up --locale`), whatever the page shows. */
export const SPOKEN_LOCALE = inBrowser ? chooseLocale(null, [document.documentElement.dataset.locale ?? DEFAULT_LOCALE]) : DEFAULT_LOCALE;

/** The shown locale's words; null for English, which the scripts are written in. */
const SHOWN = inBrowser && LOCALE !== DEFAULT_LOCALE ? await wordsOf(LOCALE) : null;
/** The assistant's language's words, for what the page says to it on the reader's behalf. */
const SPOKEN = SPOKEN_LOCALE === LOCALE ? SHOWN : inBrowser && SPOKEN_LOCALE !== DEFAULT_LOCALE ? await wordsOf(SPOKEN_LOCALE) : null;

/**
 * `english` in the page's language, its `{name}` placeholders filled from `values`.
 * @param {string} english
 * @param {Record<string, string | number>} [values]
 * @returns {string}
 */
export function t(english, values = {}) {
  const template = SHOWN?.strings?.[english] ?? english;
  return template.replace(/\{(\w+)\}/g, (whole, name) => (name in values ? String(values[name]) : whole));
}

/**
 * What the page says to the assistant for the reader ("send a robot to {zone}"), in the
 * assistant's language, which may not be the page's.
 * @param {string} english
 * @param {Record<string, string | number>} [values]
 */
export function said(english, values = {}) {
  const template = SPOKEN?.utterances?.[english] ?? english;
  return template.replace(/\{(\w+)\}/g, (whole, name) => (name in values ? String(values[name]) : whole));
}

/**
 * `english`'s translation with its `{name}` placeholders replaced by nodes (keys as <kbd>),
 * in the order the language puts them: "hold {space} to talk", "{space} halten zum Sprechen".
 * @param {string} english
 * @param {Record<string, Node>} nodes
 * @returns {Node[]}
 */
export function tNodes(english, nodes) {
  const template = SHOWN?.strings?.[english] ?? english;
  return template.split(/(\{\w+\})/).filter(Boolean).map((part) => {
    const name = part.match(/^\{(\w+)\}$/)?.[1];
    return name && nodes[name] ? nodes[name] : document.createTextNode(part);
  });
}

async function start() {
  const locale = LOCALE;
  const shown = SHOWN ?? (await wordsOf(locale));
  const names = Object.fromEntries(
    await Promise.all(SUPPORTED.map(async (code) => [code, code === locale ? shown.name : (await wordsOf(code)).name])),
  );
  if (locale !== DEFAULT_LOCALE) {
    applyWords(document, shown);
    document.documentElement.lang = shown.lang;
  }
  addSelector(locale, names, shown.language_label);
}

if (typeof document !== "undefined" && typeof window !== "undefined") {
  if (document.readyState === "loading") document.addEventListener("DOMContentLoaded", () => void start());
  else void start();
}
