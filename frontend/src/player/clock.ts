// Playback time as a pure function: given the frame we were on, how long the last
// animation frame took and the playback settings, which frame is shown next.

export interface Playback {
  /** Fractional frame position (the shown frame is its floor). */
  position: number;
  playing: boolean;
  speed: number;
  fps: number;
  nFrames: number;
  /** Half-open [start, stop) loop range, or null to play to the end and stop. */
  loop: { start: number; stop: number } | null;
}

export const SPEEDS = [0.1, 0.25, 0.5, 1, 1.5, 2, 4];

export function advance(p: Playback, dtSeconds: number): Playback {
  if (!p.playing) return p;
  // A tab in the background can report a multi-second frame; do not leap the playhead.
  const dt = Math.min(Math.max(dtSeconds, 0), 0.25);
  let position = p.position + dt * p.fps * p.speed;
  if (p.loop && p.loop.stop - p.loop.start >= 1) {
    const { start, stop } = p.loop;
    if (position >= stop || position < start) position = start + ((((position - start) % (stop - start)) + (stop - start)) % (stop - start));
    return { ...p, position };
  }
  if (position >= p.nFrames - 1) return { ...p, position: p.nFrames - 1, playing: false };
  return { ...p, position };
}

export function frameOf(p: Playback): number {
  return Math.min(Math.max(Math.floor(p.position), 0), Math.max(p.nFrames - 1, 0));
}

export function seek(p: Playback, frame: number): Playback {
  return { ...p, position: Math.min(Math.max(Math.round(frame), 0), Math.max(p.nFrames - 1, 0)) };
}

export function togglePlay(p: Playback): Playback {
  // Pressing play on the last frame starts again from the top (or the loop start).
  const atEnd = !p.loop && frameOf(p) >= p.nFrames - 1;
  return { ...p, playing: !p.playing, position: !p.playing && atEnd ? 0 : p.position };
}

export function nextSpeed(speed: number, direction: -1 | 1): number {
  const i = SPEEDS.findIndex((s) => s >= speed - 1e-9);
  const at = i < 0 ? SPEEDS.length - 1 : i;
  return SPEEDS[Math.min(Math.max(at + direction, 0), SPEEDS.length - 1)];
}
