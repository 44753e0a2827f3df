// Where things are on the timeline canvas and what a pointer there may do. Pure, so the
// rule "a click on the ruler always seeks; a cut is grabbed only on its own handle" is
// unit-tested without a browser.
//
//   ruler      time ticks. Click / drag: seek. Shift+drag: loop a range.
//   handles    one handle per kept cut (deleted candidates: a small ×). Grab a handle to
//              select the cut, drag it past a threshold to move it; elsewhere: seek.
//   lanes      feature signals and segment bands. Click / drag: seek; double-click: insert.
//   overview   the whole take: candidate density, labels, the working window. Click /
//              drag: seek there; the working window follows.

export const RULER = 24;
export const HANDLES = 16;
export const LANE = 70;
export const SEGMENTS = 30;
export const OVERVIEW = 24;
export const GAP = 6;
/** A handle is this many pixels either side of its cut. */
export const HANDLE_HALF = 6;
/** A handle moves its cut only once dragged further than this: a click never moves it. */
export const DRAG_THRESHOLD_PX = 5;
/** Fewer pixels than this per kept cut in view: the cuts are too dense to draw or grab one by one. */
export const DENSE_PX_PER_CUT = 10;

export type Zone = "ruler" | "handles" | "lanes" | "overview";

export interface Rows {
  handlesTop: number;
  lanes: { top: number; height: number }[];
  segTop: number;
  overviewTop: number;
  height: number;
}

/** The vertical layout for `nLanes` signal lanes (at least one row is kept for a message). */
export function rows(nLanes: number): Rows {
  const n = Math.max(nLanes, 1);
  const handlesTop = RULER;
  const lanesTop = RULER + HANDLES + GAP;
  const lanes = Array.from({ length: n }, (_, i) => ({ top: lanesTop + i * (LANE + GAP), height: LANE }));
  const segTop = lanesTop + n * (LANE + GAP);
  const overviewTop = segTop + SEGMENTS + GAP;
  return { handlesTop, lanes, segTop, overviewTop, height: overviewTop + OVERVIEW + 2 };
}

export function zoneAt(r: Rows, y: number): Zone {
  if (y < r.handlesTop) return "ruler";
  if (y < r.handlesTop + HANDLES) return "handles";
  if (y < r.overviewTop) return "lanes";
  return "overview";
}

/** True when `keptInView` cuts across `width` pixels are too close to grab or read one by one. */
export function denseCuts(keptInView: number, width: number): boolean {
  return keptInView > 0 && width / keptInView < DENSE_PX_PER_CUT;
}

export interface HandleCut {
  id: number;
  x: number;
}

/**
 * The cut whose handle is under (x, y), or null. Only the handle strip grabs a cut; the
 * ruler and the lanes never do, nor does any handle while the cuts are dense. Of two
 * handles under the pointer the nearer wins, the selected one on a tie.
 */
export function hitHandle(r: Rows, cuts: readonly HandleCut[], x: number, y: number, dense: boolean, selectedId: number | null): number | null {
  if (dense || zoneAt(r, y) !== "handles") return null;
  let best: number | null = null;
  let bestDistance = Infinity;
  for (const cut of cuts) {
    const d = Math.abs(cut.x - x) - (cut.id === selectedId ? 0.5 : 0);
    if (d <= HANDLE_HALF && d < bestDistance) [best, bestDistance] = [cut.id, d];
  }
  return best;
}

/** Whether a pointer that went down at `startX` and is now at `x` has become a drag. */
export function isDrag(startX: number, x: number): boolean {
  return Math.abs(x - startX) > DRAG_THRESHOLD_PX;
}

/** The frame under pixel `x` of the overview, which always shows the whole take. */
export function overviewFrame(x: number, width: number, nFrames: number): number {
  const frame = Math.round((x / Math.max(width, 1)) * nFrames);
  return Math.min(Math.max(frame, 0), Math.max(nFrames - 1, 0));
}

export function overviewX(frame: number, width: number, nFrames: number): number {
  return (frame / Math.max(nFrames, 1)) * width;
}

/** How many frames fall in each pixel column of the overview: the density of `frames`. */
export function density(frames: readonly number[], width: number, nFrames: number): Uint16Array {
  const out = new Uint16Array(Math.max(Math.ceil(width), 1));
  for (const f of frames) {
    const c = Math.min(Math.max(Math.floor(overviewX(f, width, nFrames)), 0), out.length - 1);
    if (out[c] < 65535) out[c]++;
  }
  return out;
}
