// @ts-check
// A long list that only has elements for the rows in view: a thousand robots are a
// thousand rows to scroll through but a few dozen elements to lay out. Rows have one
// height; the list's own height is that of every row, so the scroll bar tells the truth.

/**
 * The rows to draw: those in view plus `overscan` on each side.
 * @param {number} scrollTop
 * @param {number} viewport the list's visible height
 * @param {number} rowHeight
 * @param {number} count
 * @param {number} [overscan]
 * @returns {{first: number, last: number}} `last` is one past the last row
 */
export function rowsInView(scrollTop, viewport, rowHeight, count, overscan = 4) {
  const first = Math.max(0, Math.floor(scrollTop / rowHeight) - overscan);
  const last = Math.min(count, Math.ceil((scrollTop + viewport) / rowHeight) + overscan);
  return { first, last: Math.max(first, last) };
}

/**
 * The scroll position that brings row `index` into view, moving as little as possible.
 * @param {number} index
 * @param {number} scrollTop
 * @param {number} viewport
 * @param {number} rowHeight
 */
export function scrollToShow(index, scrollTop, viewport, rowHeight) {
  const top = index * rowHeight;
  if (top < scrollTop) return top;
  if (top + rowHeight > scrollTop + viewport) return top + rowHeight - viewport;
  return scrollTop;
}

/**
 * A scrolling list (`box`) of `count` rows of `rowHeight` pixels; `make` builds a row
 * element, `bind` fills one with row `index`'s content.
 * @template {HTMLElement} R
 */
export class VirtualList {
  /**
   * @param {HTMLElement} box
   * @param {number} rowHeight
   * @param {{make: () => R, bind: (row: R, index: number) => void}} rows
   */
  constructor(box, rowHeight, { make, bind }) {
    this.box = box;
    this.rowHeight = rowHeight;
    this.make = make;
    this.bind = bind;
    this.count = 0;
    /** @type {R[]} */
    this.pool = [];
    this.first = 0;
    this.spacer = document.createElement("li");
    this.spacer.className = "virtual-spacer";
    this.spacer.setAttribute("aria-hidden", "true");
    box.replaceChildren(this.spacer);
    box.addEventListener("scroll", () => this.refresh(), { passive: true });
  }

  /** @param {number} count */
  setCount(count) {
    this.count = count;
    this.spacer.style.height = `${count * this.rowHeight}px`;
    this.refresh();
  }

  // Bind the rows in view (after a scroll, a resize, or new rows).
  refresh() {
    const { first, last } = rowsInView(this.box.scrollTop, this.box.clientHeight || 400, this.rowHeight, this.count);
    while (this.pool.length < last - first) {
      const row = this.make();
      this.pool.push(row);
      this.box.appendChild(row);
    }
    this.first = first;
    this.pool.forEach((row, slot) => {
      const index = first + slot;
      row.hidden = index >= last;
      if (index < last) {
        row.style.transform = `translateY(${index * this.rowHeight}px)`;
        this.bind(row, index);
      }
    });
  }

  /** Scroll so that row `index` is in view. @param {number} index */
  show(index) {
    const top = scrollToShow(index, this.box.scrollTop, this.box.clientHeight, this.rowHeight);
    if (top !== this.box.scrollTop) this.box.scrollTop = top;
    this.refresh();
  }
}
