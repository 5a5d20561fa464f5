// Small helpers every view uses: making an element, and a time of day as the page shows it.

export function node(tag, className, content) {
  const made = document.createElement(tag);
  if (className) made.className = className;
  if (content !== undefined) made.textContent = content;
  return made;
}

// "14:03:27" for a time in milliseconds since the epoch (or an ISO string); `none` if absent.
export function clock(at, none = "") {
  if (at === undefined || at === null) return none;
  return new Date(at).toLocaleTimeString([], { hour: "2-digit", minute: "2-digit", second: "2-digit" });
}
