// @ts-check
// The station's API from the page: JSON requests, and speaking a reply aloud.

/** @import { Heard } from "./contract.js" */

/**
 * The assistant's answer to an utterance (`/api/say`, and the turn of a push-to-talk).
 * @typedef {object} SayReply
 * @property {string} speech
 * @property {string | null} [intent]
 * @property {string[]} [commands]
 */

/**
 * What push-to-talk heard and what came of it (`/api/voice`).
 * @typedef {object} VoiceReply
 * @property {Heard} heard
 * @property {number} recognizer_ms
 * @property {boolean} understood
 * @property {string} speech
 * @property {SayReply | null} turn
 */

/** The id of a command the station sent (`/api/command`, `/api/stop`). @typedef {{id: string}} CommandReply */

/**
 * Who works the page (`/api/me`): their Alexa id, name and role, the kinds of action the
 * role allows, and whether they signed in (else everyone may do everything here).
 * @typedef {object} Operator
 * @property {string} id
 * @property {string | null} name
 * @property {string} role
 * @property {string[]} may
 * @property {boolean} signed_in
 */

export class ApiError extends Error {}

/** What went wrong, in words (an ApiError's message says it). @param {unknown} err */
export function reason(err) {
  return (err instanceof Error && err.message) || String(err);
}

/**
 * POST `body` as JSON to the station; resolves with its JSON answer, rejects with an ApiError
 * that says why in words.
 * @template [T=unknown]
 * @param {string} path
 * @param {object} [body]
 * @returns {Promise<T>}
 */
export async function post(path, body) {
  let response;
  try {
    response = await fetch(path, {
      method: "POST",
      headers: { "Content-Type": "application/json" },
      body: JSON.stringify(body ?? {}),
    });
  } catch (err) {
    throw new ApiError("The station does not answer; is it still running?");
  }
  return answer(response);
}

/**
 * GET `path` from the station; resolves with its JSON answer, rejects with an ApiError.
 * @template [T=unknown]
 * @param {string} path
 * @returns {Promise<T>}
 */
export async function get(path) {
  let response;
  try {
    response = await fetch(path);
  } catch (err) {
    throw new ApiError("The station does not answer; is it still running?");
  }
  return answer(response);
}

/** @param {Blob} blob a WAV file @returns {Promise<VoiceReply>} */
export async function postWav(blob) {
  let response;
  try {
    response = await fetch("/api/voice", {
      method: "POST",
      headers: { "Content-Type": "audio/wav" },
      body: blob,
    });
  } catch (err) {
    throw new ApiError("The station does not answer; is it still running?");
  }
  return answer(response);
}

/** @param {Response} response @returns {Promise<any>} */
async function answer(response) {
  /** @type {{error?: string}} */
  let body = {};
  try {
    body = await response.json();
  } catch (err) {
    body = {};
  }
  if (!response.ok) {
    throw new ApiError(body.error || `The station answered ${response.status}.`);
  }
  return body;
}

// How replies are spoken: the browser's own voice, espeak-ng on the station's computer
// (its audio played here), or not at all. Remembered in this browser.
const VOICE_KEY = "vahr-station-reply-voice";

export function replyVoice() {
  const chosen = localStorage.getItem(VOICE_KEY);
  if (chosen) return chosen;
  // Without any browser voice (a headless browser, some tablets) espeak-ng is the default.
  const voices = "speechSynthesis" in window ? speechSynthesis.getVoices() : [];
  return voices.length ? "browser" : "espeak";
}

/** @param {string} value */
export function setReplyVoice(value) {
  localStorage.setItem(VOICE_KEY, value);
}

/** @type {HTMLAudioElement | null} */
let playing = null;
/** @type {((value?: unknown) => void) | null} */
let finishPlaying = null;

// Stop speaking at once (the person pressed to talk again).
export function hush() {
  if ("speechSynthesis" in window) speechSynthesis.cancel();
  if (playing) playing.pause();
  finishPlaying?.();
}

// Speak `text`; resolves when it has been spoken (or at once when muted or on failure).
/** @param {string | null | undefined} text */
export async function speak(text) {
  if (!text) return;
  const voice = replyVoice();
  if (voice === "off") return;
  if (voice === "browser" && "speechSynthesis" in window && speechSynthesis.getVoices().length) {
    await new Promise((resolve) => {
      const utterance = new SpeechSynthesisUtterance(text);
      utterance.onend = resolve;
      utterance.onerror = resolve;
      speechSynthesis.cancel();
      speechSynthesis.speak(utterance);
    });
    return;
  }
  let response;
  try {
    response = await fetch("/api/speech", {
      method: "POST",
      headers: { "Content-Type": "application/json" },
      body: JSON.stringify({ text }),
    });
  } catch (err) {
    return;
  }
  if (!response.ok) return;
  const url = URL.createObjectURL(await response.blob());
  try {
    if (playing) playing.pause();
    const audio = new Audio(url);
    playing = audio;
    await new Promise((resolve) => {
      finishPlaying = resolve;
      audio.onended = resolve;
      audio.onerror = resolve;
      audio.play().catch(resolve);
    });
    finishPlaying = null;
  } finally {
    URL.revokeObjectURL(url);
  }
}
