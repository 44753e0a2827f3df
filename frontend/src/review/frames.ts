// Joint positions for playback, fetched in chunks (the API serves at most 5,000 frames
// per request, fewer for many joints, continuing from its "stop") into one Float32Array so a 72,000-frame take never builds JS objects
// per frame. The chunk under the playhead comes first; the rest stream in after it.

import { get } from "../api/client";
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

/**
 * Fill `store` chunk by chunk, two requests in flight (the server is small), calling
 * `onChunk` after each so the player and progress bar can update. After each chunk a
 * request waits for `gate`: the page holds the rest of the poses back while it fetches
 * what it draws next, so that request does not queue behind pose chunks.
 */
export async function loadFrames(captureId: number, store: FrameStore, firstFrame: number, onChunk: () => void, signal?: AbortSignal, gate: Promise<void> = Promise.resolve()): Promise<void> {
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
