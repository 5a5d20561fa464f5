// @ts-check
// Push-to-talk: hold the button (or the space bar), speak, let go. The page records the
// microphone as 16 kHz mono 16-bit PCM, sends it as a WAV file, and shows what was heard,
// how sure the recognizer was, and the assistant's reply, which it then speaks.

import { t } from "./i18n.js";
import { ApiError, hush, postWav, reason, speak } from "./api.js";

/** @import { VoiceReply } from "./api.js" */
/** @import { Interaction, Interactions } from "./interactions.js" */
/** @import { Metrics } from "./station.js" */

/**
 * One push-to-talk under way: the microphone's blocks so far, and the interaction it is.
 * @typedef {object} Recording
 * @property {Float32Array[]} chunks
 * @property {number} pressedAt
 * @property {Interaction} interaction
 * @property {boolean} released
 * @property {Promise<void> | null} ready resolves once the microphone is open (or failed to)
 * @property {unknown} [error] why the microphone did not open
 * @property {{stream: MediaStream, context: AudioContext, source: MediaStreamAudioSourceNode, capture: AudioWorkletNode} | null} [audio]
 */

const RATE = 16000;
const SHORTEST_MS = 300;

/** A 16 kHz mono 16-bit WAV file of the blocks recorded at `rate`. @param {Float32Array[]} chunks @param {number} rate */
export function wavFile(chunks, rate) {
  let length = 0;
  for (const chunk of chunks) length += chunk.length;
  const samples = new Float32Array(length);
  let offset = 0;
  for (const chunk of chunks) { samples.set(chunk, offset); offset += chunk.length; }
  const pcm = rate === RATE ? samples : resample(samples, rate, RATE);
  const buffer = new ArrayBuffer(44 + pcm.length * 2);
  const view = new DataView(buffer);
  const ascii = (/** @type {number} */ at, /** @type {string} */ text) => { for (let i = 0; i < text.length; i += 1) view.setUint8(at + i, text.charCodeAt(i)); };
  ascii(0, "RIFF"); view.setUint32(4, 36 + pcm.length * 2, true); ascii(8, "WAVE");
  ascii(12, "fmt "); view.setUint32(16, 16, true); view.setUint16(20, 1, true); view.setUint16(22, 1, true);
  view.setUint32(24, RATE, true); view.setUint32(28, RATE * 2, true); view.setUint16(32, 2, true); view.setUint16(34, 16, true);
  ascii(36, "data"); view.setUint32(40, pcm.length * 2, true);
  for (let i = 0; i < pcm.length; i += 1) {
    const s = Math.max(-1, Math.min(1, pcm[i]));
    view.setInt16(44 + i * 2, s < 0 ? s * 0x8000 : s * 0x7fff, true);
  }
  return new Blob([buffer], { type: "audio/wav" });
}

/** @param {Float32Array} samples @param {number} from @param {number} to */
function resample(samples, from, to) {
  const out = new Float32Array(Math.floor((samples.length * to) / from));
  for (let i = 0; i < out.length; i += 1) {
    const at = (i * from) / to;
    const left = Math.floor(at);
    const right = Math.min(left + 1, samples.length - 1);
    out[i] = samples[left] + (samples[right] - samples[left]) * (at - left);
  }
  return out;
}

export class Talk {
  /**
   * @param {object} parts
   * @param {HTMLButtonElement} parts.button the button to hold (it holds a `.talk-label`)
   * @param {HTMLElement} parts.level the level meter
   * @param {HTMLElement} parts.state what was heard and answered
   * @param {Interactions} parts.interactions
   * @param {Metrics | null} parts.metrics
   */
  constructor({ button, level, state, interactions, metrics }) {
    this.button = button;
    this.label = /** @type {HTMLElement} */ (button.querySelector(".talk-label"));
    this.level = level;
    this.state = state;
    this.interactions = interactions;
    this.metrics = metrics;
    /** @type {Recording | null} */
    this.recording = null;
    this.busy = false;
    if (!navigator.mediaDevices?.getUserMedia) {
      button.disabled = true;
      this.say(t("Push-to-talk needs a microphone and a secure page: open the station on this computer (http://127.0.0.1) or over https."));
      return;
    }
    button.addEventListener("pointerdown", (event) => {
      if (event.button !== 0) return;
      event.preventDefault();
      button.setPointerCapture?.(event.pointerId);
      this.press("button");
    });
    for (const kind of /** @type {const} */ (["pointerup", "pointercancel", "lostpointercapture"])) {
      button.addEventListener(kind, () => this.release());
    }
    button.addEventListener("keydown", (event) => { if (event.key === "Enter" && !event.repeat) this.press("key"); });
    button.addEventListener("keyup", (event) => { if (event.key === "Enter") this.release(); });
    document.addEventListener("keydown", (event) => {
      if (event.code !== "Space" || event.repeat || typing(event.target)) return;
      event.preventDefault();
      this.press("key");
    });
    document.addEventListener("keyup", (event) => {
      if (event.code !== "Space" || typing(event.target)) return;
      event.preventDefault();
      this.release();
    });
  }

  /** @param {string} html */
  say(html) {
    this.state.textContent = html;
  }

  /** @param {"button" | "key"} how */
  async press(how) {
    if (this.recording || this.busy) return;
    hush(); // pressing again cuts the last reply short
    const pressedAt = Date.now();
    const interaction = this.interactions.start("voice", "push-to-talk", pressedAt);
    /** @type {Recording} */
    const recording = { chunks: [], pressedAt, interaction, released: false, ready: null };
    this.recording = recording;
    this.button.dataset.state = "listening";
    this.label.textContent = t("Listening… let go to send");
    this.say(t("Listening…"));
    recording.ready = this.open(recording).catch((err) => {
      recording.error = err;
    });
  }

  /** @param {Recording} recording */
  async open(recording) {
    const stream = await navigator.mediaDevices.getUserMedia({ audio: { channelCount: 1, echoCancellation: false, noiseSuppression: false, autoGainControl: false } });
    const context = new AudioContext({ sampleRate: RATE });
    await context.audioWorklet.addModule("/static/capture-worklet.js");
    const source = context.createMediaStreamSource(stream);
    const capture = new AudioWorkletNode(context, "capture");
    capture.port.onmessage = (message) => {
      if (recording.released) return;
      recording.chunks.push(message.data.samples);
      this.level.style.width = `${Math.min(100, Math.round(message.data.peak * 140))}%`;
    };
    source.connect(capture);
    recording.audio = { stream, context, source, capture };
    if (recording.released) this.close(recording);
  }

  /** @param {Recording} recording */
  close(recording) {
    const audio = recording.audio;
    if (!audio) return;
    audio.source.disconnect();
    audio.capture.port.onmessage = null;
    for (const track of audio.stream.getTracks()) track.stop();
    audio.context.close();
    recording.audio = null;
  }

  async release() {
    const recording = this.recording;
    if (!recording || recording.released) return;
    recording.released = true;
    const releasedAt = performance.now();
    this.recording = null;
    this.level.style.width = "0";
    await recording.ready;
    this.close(recording);
    const rate = RATE;
    this.busy = true;
    this.button.dataset.state = "thinking";
    this.label.textContent = t("Understanding…");
    const { interaction } = recording;
    interaction.counts = true;
    try {
      if (recording.error) throw new ApiError(t("The microphone is not available: {why}", { why: reason(recording.error) }));
      if (Date.now() - recording.pressedAt < SHORTEST_MS || !recording.chunks.length) {
        interaction.counts = false;
        this.say(t("Hold the button while you speak, and let go when you are done."));
        return;
      }
      const result = await postWav(wavFile(recording.chunks, rate));
      this.show(result);
      this.metrics?.ptt.push({ reply_shown_ms: performance.now() - releasedAt, recognizer_ms: result.recognizer_ms, transcript: result.heard.transcript });
      const turn = result.turn;
      interaction.text = result.heard.transcript || "(nothing heard)";
      interaction.speech = result.speech;
      interaction.intent = turn?.intent ?? null;
      interaction.commands = turn?.commands ?? [];
      interaction.asks = turn?.intent === "WeatherIntent";
      if (!result.understood) interaction.error = "not understood";
      this.idle();
      // The exchange lasts until the reply has been heard (or cut short by a new press).
      await speak(result.speech);
    } catch (err) {
      interaction.error = reason(err);
      this.say(reason(err));
    } finally {
      this.idle();
      this.interactions.end(interaction, Date.now());
    }
  }

  idle() {
    this.busy = false;
    if (this.recording) return;
    this.button.dataset.state = "idle";
    this.label.textContent = t("Hold to talk");
  }

  /** @param {VoiceReply} result */
  show(result) {
    const { heard } = result;
    this.state.replaceChildren();
    if (heard.transcript) {
      const said = document.createElement("span");
      said.className = "transcript";
      said.textContent = `“${heard.transcript}”`;
      this.state.append(`${t("Heard")} `, said, ` (${t("{sure}% sure", { sure: Math.round(heard.confidence * 100) })}). `);
    } else {
      this.state.append(`${t("Heard no speech.")} `);
    }
    const reply = document.createElement("span");
    reply.className = "reply";
    reply.dataset.understood = String(result.understood);
    reply.textContent = result.speech;
    this.state.append(reply);
  }
}

/** True when `target` takes text (a key there is typing, not a command). @param {EventTarget | null} target */
export function typing(target) {
  return target instanceof HTMLElement && (target.isContentEditable || ["INPUT", "TEXTAREA", "SELECT"].includes(target.tagName));
}
