// Where the annotators disagree, as pure functions over their submitted reviews:
// - a cut is "agreed" when every other tier has a cut within the tolerance, "shifted" when
//   every other tier has a matching cut but at least one is further than the tolerance
//   (within three tolerances), and "lone" when some tier has no cut near it at all;
// - label disagreements are the frame ranges where the tiers' labels differ.

import type { Draft } from "../library/gold";
import type { Span } from "../library/types";

export type CutMark = "agreed" | "shifted" | "lone";

/** How far apart two cuts may be and still be the same boundary, shifted. */
export const MATCH_WINDOW = 3;

function nearest(cuts: number[], frame: number): number {
  let best = Infinity;
  for (const c of cuts) best = Math.min(best, Math.abs(c - frame));
  return best;
}

/** One mark per cut of each tier. `tolerance` in frames. */
export function cutMarks(tiers: number[][], tolerance: number): CutMark[][] {
  return tiers.map((cuts, i) =>
    cuts.map((frame) => {
      const distances = tiers.filter((_, j) => j !== i).map((other) => nearest(other, frame));
      if (distances.every((d) => d <= tolerance)) return "agreed";
      if (distances.every((d) => d <= tolerance * MATCH_WINDOW)) return "shifted";
      return "lone";
    }),
  );
}

/** Frame ranges [start, stop) where the tiers do not all carry the same label. */
export function labelConflicts(tiers: Span[][], nFrames: number): { start: number; stop: number }[] {
  if (tiers.length < 2) return [];
  const bounds = [...new Set([0, nFrames, ...tiers.flatMap((t) => t.flatMap((s) => [s.start, s.stop]))])]
    .filter((f) => f >= 0 && f <= nFrames)
    .sort((a, b) => a - b);
  const labelAt = (tier: Span[], frame: number) => tier.find((s) => s.start <= frame && frame < s.stop)?.label ?? null;
  const out: { start: number; stop: number }[] = [];
  for (let k = 0; k + 1 < bounds.length; k++) {
    const [start, stop] = [bounds[k], bounds[k + 1]];
    const labels = new Set(tiers.map((t) => labelAt(t, start)));
    if (labels.size < 2) continue;
    const last = out[out.length - 1];
    if (last && last.stop === start) last.stop = stop;
    else out.push({ start, stop });
  }
  return out;
}

/** The frame to snap a dragged gold cut to: the nearest tier cut within `reach` frames, else `frame`. */
export function snapToCuts(frame: number, cuts: number[], reach: number): number {
  let best = frame;
  let bestDistance = reach + 1;
  for (const c of cuts) {
    const d = Math.abs(c - frame);
    if (d <= reach && d < bestDistance) {
      best = c;
      bestDistance = d;
    }
  }
  return best;
}

/** Undo/redo over whole gold drafts: small, and a draft is a few dozen numbers. */
export interface Timeline<T> {
  past: T[];
  present: T;
  future: T[];
}

export const start = <T>(present: T): Timeline<T> => ({ past: [], present, future: [] });
export const push = <T>(h: Timeline<T>, next: T): Timeline<T> => ({ past: [...h.past, h.present], present: next, future: [] });
export const back = <T>(h: Timeline<T>): Timeline<T> =>
  h.past.length ? { past: h.past.slice(0, -1), present: h.past[h.past.length - 1], future: [h.present, ...h.future] } : h;
export const forward = <T>(h: Timeline<T>): Timeline<T> =>
  h.future.length ? { past: [...h.past, h.present], present: h.future[0], future: h.future.slice(1) } : h;

/** Start of the nearest gold segment without a label after (1) or before (-1) `frame`. */
export function unlabelledGold(draft: Draft, frame: number, direction: -1 | 1): number | null {
  const starts = [0, ...draft.cuts];
  const order = direction > 0 ? starts.map((_, i) => i) : starts.map((_, i) => starts.length - 1 - i);
  for (const i of order) {
    if (draft.labels[i] !== null) continue;
    if (direction > 0 ? starts[i] > frame : starts[i] < frame) return starts[i];
  }
  return null;
}
