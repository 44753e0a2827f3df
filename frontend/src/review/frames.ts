// Joint positions for playback, into one Float32Array so an hour-long take never builds JS
// objects per frame. The poses come as raw little-endian float32 from /poses/: a small first
// answer at the playhead (a pose on screen at once), then the rest as two streamed answers
// (after the playhead, before it) whose bytes land in the array as they arrive. The JSON
// /frames/ path (base64 chunks of at most 5,000 frames) stays for `?poses=json`, so a
// benchmark can time both in the same run.

import { ApiError, errorText, get, isLoggedOut, retryDelay, toLogin } from "../api/client";
import type { FramesResponse } from "../api/types";

export const CHUNK = 5000;

const LITTLE_ENDIAN = new Uint8Array(new Uint16Array([1]).buffer)[0] === 1;

/** Decode the API's base64 little-endian float32 payload. */
export function decodeFloat32(base64: string): Float32Array {
  const binary = atob(base64);
  const bytes = new Uint8Array(binary.length);
  for (let i = 0; i < binary.length; i++) bytes[i] = binary.charCodeAt(i);
  if (bytes.length % 4 !== 0) throw new Error(`Frame data is ${bytes.length} bytes, not a whole number of float32 values.`);
  if (LITTLE_ENDIAN) return new Float32Array(bytes.buffer);
  const view = new DataView(bytes.buffer);
  const out = new Float32Array(bytes.length / 4);
  for (let i = 0; i < out.length; i++) out[i] = view.getFloat32(i * 4, true);
  return out;
}

/** Frames in the very first request: enough to show a pose and play a few seconds. */
export const HEAD = 600;

/**
 * Chunk ranges [start, stop) covering the take, nearest to `firstFrame` first. The chunk
 * holding `firstFrame` is split so that its first `head` frames come alone: a small first
 * answer puts a pose on screen sooner.
 */
export function planChunks(nFrames: number, firstFrame = 0, chunk = CHUNK, head = 0): { start: number; stop: number }[] {
  const ranges = [];
  for (let start = 0; start < nFrames; start += chunk) ranges.push({ start, stop: Math.min(start + chunk, nFrames) });
  const centre = (r: { start: number; stop: number }) =>
    firstFrame >= r.start && firstFrame < r.stop ? -1 : Math.min(Math.abs(r.start - firstFrame), Math.abs(r.stop - 1 - firstFrame));
  ranges.sort((a, b) => centre(a) - centre(b) || a.start - b.start);
  const first = ranges[0];
  if (head > 0 && first && first.stop - first.start > head) {
    const from = Math.min(Math.max(firstFrame, first.start), first.stop - head);
    const rest = [{ start: first.start, stop: from }, { start: from + head, stop: first.stop }].filter((r) => r.stop > r.start);
    ranges.splice(0, 1, { start: from, stop: from + head }, ...rest);
  }
  return ranges;
}

export class FrameStore {
  readonly positions: Float32Array;
  private readonly loaded: Uint8Array;
  loadedFrames = 0;
  error: string | null = null;

  constructor(
    readonly nFrames: number,
    readonly nJoints: number,
  ) {
    this.positions = new Float32Array(nFrames * nJoints * 3);
    this.loaded = new Uint8Array(nFrames);
  }

  has(frame: number): boolean {
    return this.loaded[frame] === 1;
  }

  /** Positions of one frame, (n_joints, 3) flattened; a view, not a copy. */
  pose(frame: number): Float32Array {
    const size = this.nJoints * 3;
    return this.positions.subarray(frame * size, (frame + 1) * size);
  }

  /** The nearest loaded frame at or before `frame` (so playback shows something while loading). */
  nearestLoaded(frame: number): number | null {
    for (let f = frame; f >= 0; f--) if (this.loaded[f]) return f;
    for (let f = frame + 1; f < this.nFrames; f++) if (this.loaded[f]) return f;
    return null;
  }

  /** The lowest joint height (Y) over the loaded frames: where the floor is. */
  floorLevel(): number | null {
    let low = Infinity;
    const size = this.nJoints * 3;
    // Every 4th frame is plenty for a floor and keeps this cheap on long takes.
    for (let f = 0; f < this.nFrames; f += 4) {
      if (!this.loaded[f]) continue;
      // A point not seen (NaN) is skipped: NaN < low is false.
      for (let j = 1; j < size; j += 3) if (this.positions[f * size + j] < low) low = this.positions[f * size + j];
    }
    return Number.isFinite(low) ? low : null;
  }

  /**
   * Bytes `offset ..` of a /poses/ answer for frames [start, ...) (little-endian float32,
   * frame after frame): copied in place; each frame whose bytes are all in counts as
   * loaded. A chunk may end inside a value; the next one carries on from there.
   */
  receive(start: number, offset: number, chunk: Uint8Array): void {
    const frameBytes = this.nJoints * 12;
    const at = start * frameBytes + offset;
    if (at + chunk.length > this.positions.byteLength) {
      throw new Error(`Poses from frame ${start}: ${offset + chunk.length} bytes run past frame ${this.nFrames}.`);
    }
    new Uint8Array(this.positions.buffer, this.positions.byteOffset).set(chunk, at);
    if (frameBytes === 0) return;
    const done = Math.floor((offset + chunk.length) / frameBytes);
    for (let f = start + Math.floor(offset / frameBytes); f < start + done; f++) {
      if (!LITTLE_ENDIAN) swapFrame(this.positions, f * this.nJoints * 3, this.nJoints * 3);
      if (!this.loaded[f]) this.loadedFrames++;
      this.loaded[f] = 1;
    }
  }

  put(response: FramesResponse): void {
    const values = decodeFloat32(response.data);
    const count = response.n_frames;
    const size = this.nJoints * 3;
    if (response.n_joints !== this.nJoints || values.length !== count * size) {
      throw new Error(
        `Frames ${response.start}–${response.stop}: expected ${count} × ${this.nJoints} joints × 3 values, got ${values.length}.`,
      );
    }
    for (let i = 0; i < count; i++) {
      const frame = response.start + i * (response.step || 1);
      if (frame >= this.nFrames) break;
      this.positions.set(values.subarray(i * size, (i + 1) * size), frame * size);
      if (!this.loaded[frame]) this.loadedFrames++;
      this.loaded[frame] = 1;
    }
  }
}

function swapFrame(values: Float32Array, first: number, count: number): void {
  const view = new DataView(values.buffer, values.byteOffset);
  for (let i = first; i < first + count; i++) view.setFloat32(i * 4, view.getFloat32(i * 4, true), false);
}

/**
 * The /poses/ ranges [start, stop) in the order they are asked for: `head` frames at
 * `firstFrame` alone (a small first answer puts a pose on screen sooner), then the rest of
 * the take after them, then the part before them.
 */
export function planPoses(nFrames: number, firstFrame = 0, head = HEAD): { start: number; stop: number }[] {
  const from = Math.min(Math.max(firstFrame, 0), Math.max(nFrames - head, 0));
  const headStop = Math.min(from + head, nFrames);
  return [
    { start: from, stop: headStop },
    { start: headStop, stop: nFrames },
    { start: 0, stop: from },
  ].filter((r) => r.stop > r.start);
}

/** At most this often (ms) a streamed answer tells the page that more poses have landed. */
export const PROGRESS_MS = 100;

/** Whether the page was asked for the previous JSON frame chunks (`?poses=json`). */
export function posesAsJson(search = typeof location === "undefined" ? "" : location.search): boolean {
  return new URLSearchParams(search).get("poses") === "json";
}

/** GET a /poses/ range, asking again after a busy server's Retry-After as `api` does. */
async function fetchPoses(url: string, signal?: AbortSignal): Promise<Response> {
  const init: RequestInit = { headers: { Accept: "application/octet-stream, application/json" }, credentials: "same-origin", signal };
  let response = await fetch(url, init);
  for (let attempt = 0; ; attempt++) {
    const wait = retryDelay("GET", response.status, response.headers.get("Retry-After"), attempt);
    if (wait === null) break;
    await new Promise((resolve) => setTimeout(resolve, wait));
    response = await fetch(url, init);
  }
  if (!response.ok) {
    const text = await response.text();
    let body: unknown = text;
    try {
      body = JSON.parse(text);
    } catch {
      // Not JSON: the text is the message.
    }
    if (isLoggedOut(response.status, body) && typeof window !== "undefined") toLogin();
    throw new ApiError(response.status, errorText(response.status, body), body);
  }
  return response;
}

/** Stream one /poses/ range into `store`, calling `progress` as frames land. */
async function streamPoses(captureId: number, range: { start: number; stop: number }, store: FrameStore, progress: () => void, signal?: AbortSignal): Promise<void> {
  const response = await fetchPoses(`/api/captures/${captureId}/poses/?start=${range.start}&stop=${range.stop}`, signal);
  const joints = Number(response.headers.get("X-Poses-Joints"));
  if (joints !== store.nJoints) throw new Error(`Poses ${range.start}–${range.stop}: expected ${store.nJoints} joints, got ${response.headers.get("X-Poses-Joints")}.`);
  const expected = (range.stop - range.start) * store.nJoints * 12;
  let offset = 0;
  const take = (chunk: Uint8Array) => {
    store.receive(range.start, offset, chunk);
    offset += chunk.length;
    progress();
  };
  if (response.body && typeof response.body.getReader === "function") {
    const reader = response.body.getReader();
    for (let part = await reader.read(); !part.done; part = await reader.read()) take(part.value);
  } else {
    take(new Uint8Array(await response.arrayBuffer()));
  }
  if (offset !== expected) throw new Error(`Poses ${range.start}–${range.stop}: expected ${expected} bytes, got ${offset}.`);
}

/**
 * Fill `store` from /poses/: the head at `firstFrame` first (then `onChunk`), then, once
 * `gate` lets them (the page holds the rest back while it fetches what it draws next), the
 * rest of the take as two streamed answers at once, calling `onChunk` at most every
 * PROGRESS_MS while they stream and once when all is in. A failure ends loading with its
 * text in `store.error`.
 */
export async function loadFrames(captureId: number, store: FrameStore, firstFrame: number, onChunk: () => void, signal?: AbortSignal, gate: Promise<void> = Promise.resolve()): Promise<void> {
  if (posesAsJson()) return loadFramesJson(captureId, store, firstFrame, onChunk, signal, gate);
  const [head, ...rest] = planPoses(store.nFrames, firstFrame, HEAD);
  let told = 0;
  const progress = () => {
    const now = Date.now();
    if (now - told < PROGRESS_MS) return;
    told = now;
    onChunk();
  };
  try {
    if (!head) return;
    await streamPoses(captureId, head, store, () => {}, signal);
    if (signal?.aborted) return;
    onChunk();
    await gate;
    if (signal?.aborted) return;
    await Promise.all(rest.map((range) => streamPoses(captureId, range, store, progress, signal)));
    if (!signal?.aborted) onChunk();
  } catch (err) {
    if (signal?.aborted) return;
    store.error = err instanceof Error ? err.message : String(err);
    onChunk();
  }
}

/**
 * The previous loader (`?poses=json`): fill `store` chunk by chunk, two requests in flight (the server is small), calling
 * `onChunk` after each so the player and progress bar can update. After each chunk a
 * request waits for `gate`: the page holds the rest of the poses back while it fetches
 * what it draws next, so that request does not queue behind pose chunks.
 */
export async function loadFramesJson(captureId: number, store: FrameStore, firstFrame: number, onChunk: () => void, signal?: AbortSignal, gate: Promise<void> = Promise.resolve()): Promise<void> {
  const queue = planChunks(store.nFrames, firstFrame, CHUNK, HEAD);
  const worker = async () => {
    for (let range = queue.shift(); range && !signal?.aborted; range = queue.shift()) {
      const response = await get<FramesResponse>(`/api/captures/${captureId}/frames/?start=${range.start}&stop=${range.stop}&step=1`);
      if (signal?.aborted) return;
      store.put(response);
      // The server sends fewer frames per answer for a skeleton of many joints: ask for the rest next.
      if (response.stop > range.start && response.stop < range.stop) queue.unshift({ start: response.stop, stop: range.stop });
      onChunk();
      await gate;
    }
  };
  try {
    await Promise.all([worker(), worker()]);
  } catch (err) {
    store.error = err instanceof Error ? err.message : String(err);
    onChunk();
  }
}
