// @ts-check
// The task queue card: the fleet's tasks and who took which (tasks.js orders them), shown
// when the deployment has a dispatcher; "nothing queued" when its queue is empty.

import { node } from "./dom.js";
import { t } from "./i18n.js";
import { taskLines } from "./tasks.js";

/** @import { TasksMessage } from "./contract.js" */

// The words this view shows (one place, for translation).
const WORDS = {
  empty: t("Nothing queued: every task has a robot."),
  /** @param {number} queued @param {number} doing */
  count: (queued, doing) => t("{queued} queued · {doing} under way", { queued, doing }),
  status: { queued: t("queued"), assigned: t("under way"), done: t("done"), cancelled: t("cancelled") },
};

export class TasksView {
  /**
   * @param {{card: HTMLElement, list: HTMLElement, count: HTMLElement}} parts
   * @param {{nameOf: (thing: string) => string, zoneOf: (zone: string) => string}} words
   */
  constructor({ card, list, count }, { nameOf, zoneOf }) {
    this.card = card;
    this.list = list;
    this.count = count;
    this.nameOf = nameOf;
    this.zoneOf = zoneOf;
  }

  /** @param {TasksMessage | null | undefined} message */
  update(message) {
    this.card.hidden = !message?.available;
    if (!message?.available) return;
    const lines = taskLines(message.tasks, this.nameOf, this.zoneOf);
    const items = lines.map((line) => {
      const item = node("li", "task-line");
      item.dataset.status = line.status;
      item.dataset.task = line.id;
      item.append(node("span", "task-state", WORDS.status[line.status]), node("span", "task-what", line.what), node("span", "task-who", line.who));
      return item;
    });
    if (!items.length) items.push(node("li", "task-empty", WORDS.empty));
    this.list.replaceChildren(...items);
    const queued = lines.filter((l) => l.status === "queued").length;
    this.count.textContent = WORDS.count(queued, lines.filter((l) => l.status === "assigned").length);
  }
}
