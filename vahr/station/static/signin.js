// @ts-check
// The sign-in page: a person gives the token they were handed for this station; the station
// sets its cookie and the page opens the station.

import { post, reason } from "./api.js";
import { byId } from "./dom.js";

const form = byId("signin-form", HTMLFormElement);
const input = byId("signin-token", HTMLInputElement);
const problem = byId("signin-error", HTMLElement);

form.addEventListener("submit", async (event) => {
  event.preventDefault();
  problem.hidden = true;
  try {
    await post("/api/signin", { token: input.value.trim() });
    location.replace("/");
  } catch (err) {
    problem.textContent = reason(err);
    problem.hidden = false;
    input.select();
  }
});
input.focus();
