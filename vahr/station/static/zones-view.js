// @ts-check
// The zones card: one switch a zone, pressed while the zone is closed. A press closes or
// opens the zone at the fleet's dispatcher (`POST /api/zone`), which then sends no robot
// there; the map draws it closed. Shown when the deployment has a dispatcher.

import { node } from "./dom.js";
import { t } from "./i18n.js";

/** @import { FleetView, TasksMessage } from "./contract.js" */

// The words this view shows, in the page's language.
const WORDS = {
  /** @param {string} zone @param {boolean} closed */
  label: (zone, closed) => (closed ? t("{zone} is closed: open it", { zone }) : t("{zone} is open: close it", { zone })),
  /** @param {number} count */
  count: (count) => (count ? t("{count} closed", { count }) : t("all open")),
};

export class ZonesView {
  /**
   * @param {{card: HTMLElement, list: HTMLElement, count?: HTMLElement | null}} parts
   * @param {{onSwitch: (zone: string, closed: boolean) => unknown}} handlers
   */
  constructor({ card, list, count = null }, { onSwitch }) {
    this.card = card;
    this.list = list;
    this.count = count;
    this.onSwitch = onSwitch;
    /** @type {Map<string, HTMLButtonElement>} */
    this.switches = new Map();
    /** @type {Set<string>} */
    this.closed = new Set();
    // Whether the person working the page may close zones (a supervisor); else no card.
    this.allowed = true;
    this.available = false;
  }

  /** @param {boolean} allowed */
  allow(allowed) {
    this.allowed = allowed;
    this.card.hidden = !(this.available && this.allowed);
  }

  /** @param {FleetView} fleet */
  build(fleet) {
    this.switches.clear();
    const items = fleet.zones.map((zone) => {
      const button = node("button", "zone-switch", zone.id.length <= 2 ? zone.id : zone.name);
      button.type = "button";
      button.dataset.zone = zone.id;
      button.setAttribute("aria-pressed", "false");
      button.title = WORDS.label(zone.name, false);
      button.addEventListener("click", () => this.onSwitch(zone.id, !this.closed.has(zone.id)));
      this.switches.set(zone.id, button);
      return button;
    });
    this.list.replaceChildren(...items);
    this.show();
  }

  /** @param {TasksMessage | null | undefined} message */
  update(message) {
    this.available = Boolean(message?.available);
    this.card.hidden = !(this.available && this.allowed);
    this.closed = new Set(message?.closed || []);
    this.show();
  }

  show() {
    for (const [zone, button] of this.switches) {
      const closed = this.closed.has(zone);
      button.setAttribute("aria-pressed", String(closed));
      button.classList.toggle("closed", closed);
      const name = button.textContent || zone;
      button.title = WORDS.label(name.length <= 2 ? t("Zone {zone}", { zone: name }) : name, closed);
      button.setAttribute("aria-label", button.title);
    }
    if (this.count) this.count.textContent = WORDS.count(this.closed.size);
  }
}
