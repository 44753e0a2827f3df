// The gold version being edited on the adjudication page, as pure functions: a draft is
// the cut frames in increasing order and one label per segment (cuts.length + 1).

import type { Span } from "./types";

export interface Draft {
  cuts: number[];
  labels: (string | null)[];
}

/** A draft from an annotator's (or the saved gold) segments. */
export function fromSpans(spans: Span[]): Draft {
  return { cuts: spans.slice(1).map((s) => s.start), labels: spans.map((s) => s.label) };
}

export function toSpans(draft: Draft, nFrames: number): Span[] {
  const bounds = [0, ...draft.cuts, nFrames];
  return draft.labels.map((label, i) => ({ start: bounds[i], stop: bounds[i + 1], label }));
}

/** Index of the segment that contains `frame`. */
export function segmentAt(draft: Draft, frame: number): number {
  let i = 0;
  while (i < draft.cuts.length && draft.cuts[i] <= frame) i++;
  return i;
}

/** Split the segment under `frame`; both halves keep its label. No-op on an existing cut or the ends. */
export function addCut(draft: Draft, frame: number, nFrames: number): Draft {
  const f = Math.round(frame);
  if (f <= 0 || f >= nFrames || draft.cuts.includes(f)) return draft;
  const i = segmentAt(draft, f);
  const cuts = [...draft.cuts.slice(0, i), f, ...draft.cuts.slice(i)];
  const labels = [...draft.labels.slice(0, i + 1), draft.labels[i], ...draft.labels.slice(i + 1)];
  return { cuts, labels };
}

/** Remove cut `index`; the merged segment keeps the label of the segment before the cut. */
export function removeCut(draft: Draft, index: number): Draft {
  if (index < 0 || index >= draft.cuts.length) return draft;
  const cuts = draft.cuts.filter((_, i) => i !== index);
  const labels = draft.labels.filter((_, i) => i !== index + 1);
  return { cuts, labels };
}

/** Move cut `index` to `frame`, staying strictly between its neighbours. */
export function moveCut(draft: Draft, index: number, frame: number, nFrames: number): Draft {
  const low = index > 0 ? draft.cuts[index - 1] + 1 : 1;
  const high = index < draft.cuts.length - 1 ? draft.cuts[index + 1] - 1 : nFrames - 1;
  const f = Math.min(Math.max(Math.round(frame), low), high);
  return { ...draft, cuts: draft.cuts.map((c, i) => (i === index ? f : c)) };
}

export function setLabel(draft: Draft, segment: number, label: string | null): Draft {
  return { ...draft, labels: draft.labels.map((l, i) => (i === segment ? label : l)) };
}

export function sameDraft(a: Draft, b: Draft): boolean {
  return JSON.stringify(a) === JSON.stringify(b);
}
