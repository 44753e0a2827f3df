// One time axis shared by every timeline lane: which frames are in view and where they
// land in pixels. Pure functions over a small value so zoom and pan are easy to test.

export interface View {
  /** First frame at the left edge (may be fractional while zoomed). */
  start: number;
  /** Number of frames across the width. */
  span: number;
  /** Drawing width in CSS pixels. */
  width: number;
  nFrames: number;
}

/** Never zoom in further than this many frames across the lane. */
export const MIN_SPAN = 20;

export function fullView(nFrames: number, width: number): View {
  return { start: 0, span: Math.max(nFrames, 1), width, nFrames };
}

export function frameToX(view: View, frame: number): number {
  return ((frame - view.start) / view.span) * view.width;
}

export function xToFrame(view: View, x: number): number {
  return view.start + (x / view.width) * view.span;
}

/** The integer frame under pixel `x`, kept inside the take. */
export function snapFrame(view: View, x: number): number {
  const frame = Math.round(xToFrame(view, x));
  return Math.min(Math.max(frame, 0), Math.max(view.nFrames - 1, 0));
}

export function clampView(view: View): View {
  const span = Math.min(Math.max(view.span, Math.min(MIN_SPAN, view.nFrames)), Math.max(view.nFrames, 1));
  const start = Math.min(Math.max(view.start, 0), Math.max(view.nFrames - span, 0));
  return { ...view, start, span };
}

/** Zoom by `factor` (< 1 zooms in) keeping the frame under pixel `x` where it is. */
export function zoomAround(view: View, x: number, factor: number): View {
  const anchor = xToFrame(view, x);
  const span = Math.min(Math.max(view.span * factor, Math.min(MIN_SPAN, view.nFrames)), Math.max(view.nFrames, 1));
  return clampView({ ...view, span, start: anchor - (x / view.width) * span });
}

export function panBy(view: View, dxPixels: number): View {
  return clampView({ ...view, start: view.start - (dxPixels / view.width) * view.span });
}

/** Scroll just enough that `frame` is inside the view with a margin of 5 % of the span. */
export function follow(view: View, frame: number): View {
  const margin = view.span * 0.05;
  if (frame < view.start + margin) return clampView({ ...view, start: frame - margin });
  if (frame > view.start + view.span - margin) return clampView({ ...view, start: frame - view.span + margin });
  return view;
}

/**
 * Scroll by pages, as a studio editor's timeline does while playing: nothing moves until
 * `frame` leaves the view, then the view jumps so the frame sits near its left edge. The
 * view changes once a page instead of on every frame, so the drawn lanes can be reused.
 */
export function pageFollow(view: View, frame: number): View {
  if (frame >= view.start && frame <= view.start + view.span) return view;
  // Going back (a step or a jump), the frame lands near the right edge instead.
  const at = frame < view.start ? 0.95 : 0.05;
  return clampView({ ...view, start: frame - view.span * at });
}

/** Takes longer than this open on a working window instead of the whole take. */
export const LONG_TAKE_SECONDS = 300;
/** The working window's length when a long take opens. */
export const WINDOW_SECONDS = 60;

/**
 * The view a take opens on: the whole take, or for a long take a working window of
 * WINDOW_SECONDS holding `playhead` (the overview strip shows the whole take).
 */
export function openingView(nFrames: number, fps: number, width: number, playhead = 0): View {
  const whole = fullView(nFrames, width);
  if (nFrames / fps <= LONG_TAKE_SECONDS) return whole;
  return clampView({ ...whole, span: WINDOW_SECONDS * fps, start: playhead - WINDOW_SECONDS * fps * 0.05 });
}

export function resize(view: View, width: number): View {
  return { ...view, width: Math.max(width, 1) };
}

const STEPS_SECONDS = [0.01, 0.02, 0.05, 0.1, 0.2, 0.5, 1, 2, 5, 10, 15, 30, 60, 120, 300, 600, 1800, 3600];

/** Tick spacing in frames: the smallest round time step with at least `minPx` between ticks. */
export function tickStep(view: View, fps: number, minPx = 80): number {
  const pxPerFrame = view.width / view.span;
  for (const seconds of STEPS_SECONDS) {
    const frames = Math.max(1, Math.round(seconds * fps));
    if (frames * pxPerFrame >= minPx) return frames;
  }
  return Math.max(1, Math.round(STEPS_SECONDS[STEPS_SECONDS.length - 1] * fps));
}

export function ticks(view: View, fps: number, minPx = 80): number[] {
  const step = tickStep(view, fps, minPx);
  const first = Math.ceil(view.start / step) * step;
  const out: number[] = [];
  for (let f = first; f <= view.start + view.span && f <= view.nFrames; f += step) out.push(f);
  return out;
}

/** "m:ss.cc" for a frame at `fps`, e.g. frame 1234 at 120 fps → "0:10.28". */
export function formatTime(frame: number, fps: number): string {
  // Round once, in hundredths, so 59.999 s reads "1:00.00" and never "0:60.00".
  const hundredths = Math.round((frame / fps) * 100);
  const minutes = Math.floor(hundredths / 6000);
  const seconds = ((hundredths % 6000) / 100).toFixed(2).padStart(5, "0");
  return `${minutes}:${seconds}`;
}
