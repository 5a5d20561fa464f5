// @ts-check
// Small helpers every view uses: finding and making an element, and a time of day as the page
// shows it.

/**
 * The page's element `id` (index.html has every one the scripts use), of the kind expected.
 * @template {Element} T
 * @param {string} id
 * @param {{new (): T, prototype: T}} kind
 * @returns {T}
 */
export function byId(id, kind) {
  const found = document.getElementById(id);
  if (!(found instanceof kind)) throw new Error(`the page has no element #${id} of the kind its scripts expect`);
  return found;
}

/**
 * @template {keyof HTMLElementTagNameMap} K
 * @param {K} tag
 * @param {string} [className]
 * @param {string} [content]
 * @returns {HTMLElementTagNameMap[K]}
 */
export function node(tag, className, content) {
  const made = document.createElement(tag);
  if (className) made.className = className;
  if (content !== undefined) made.textContent = content;
  return made;
}

// "14:03:27" for a time in milliseconds since the epoch (or an ISO string); `none` if absent.
/** @param {number | string | null | undefined} at @param {string} [none] */
export function clock(at, none = "") {
  if (at === undefined || at === null) return none;
  return new Date(at).toLocaleTimeString([], { hour: "2-digit", minute: "2-digit", second: "2-digit" });
}
