// The review being edited, as pure functions over the API's `Review` shape.
// The page applies an edit here at once (so the screen answers immediately) and sends the
// same edit to the server; the server's answer then replaces the prediction.

import type { ApiReview, AttributeValues, Cut, Fate, Review, Segment } from "../api/types";

export type Edit =
  | { kind: "fate"; cutId: number; fate: "accepted" | "deleted" | "pending" }
  | { kind: "move"; cutId: number; frame: number }
  | { kind: "insert"; frame: number; tempId: number }
  | { kind: "label"; start: number; stop: number; label: string | null }
  // A segment attribute (review/notes.ts); not a step of the undo history.
  | { kind: "attribute"; start: number; stop: number; name: string; value: string | boolean | null }
  // Made by the server from the review's log (history.ts): the page cannot predict them.
  | { kind: "undo" }
  | { kind: "redo" }
  | { kind: "restore"; event: number };

/** Edits whose result only the server knows: the page shows its answer. */
export const isServerEdit = (edit: Edit): edit is Extract<Edit, { kind: "undo" | "redo" | "restore" }> =>
  edit.kind === "undo" || edit.kind === "redo" || edit.kind === "restore";

export class EditError extends Error {}

/**
 * A cut that is still on the timeline and bounds segments. docs/api.md counts every cut
 * that is not deleted, so a pending candidate splits segments until it is deleted.
 */
export const isKept = (cut: Cut): boolean => cut.fate !== "deleted";

export function clampFrame(frame: number, nFrames: number): number {
  return Math.min(Math.max(Math.round(frame), 0), Math.max(nFrames - 1, 0));
}

/** Visible cuts sorted by frame (ties by id so the order is stable). */
export function sortedCuts(cuts: readonly Cut[]): Cut[] {
  return cuts.filter(isKept).sort((a, b) => a.frame - b.frame || a.id - b.id);
}

/**
 * Segments between kept cuts, exactly as the server derives them: the first starts at 0,
 * each kept cut (in frame order) starts the next, the last stops at `nFrames`. The server
 * stores a label against the cut that starts its segment (null for the first segment),
 * so `labelOf` is asked by start cut id; labels thus follow a moved cut.
 */
export function deriveSegments(cuts: readonly Cut[], nFrames: number, labelOf: (startCutId: number | null) => string | null = () => null): Segment[] {
  const kept = sortedCuts(cuts);
  const starts: [number | null, number][] = [[null, 0], ...kept.map((c): [number | null, number] => [c.id, c.frame])];
  const stops = [...kept.map((c) => c.frame), nFrames];
  return starts.map(([cutId, start], index) => ({ index, start, stop: stops[index], label: labelOf(cutId) }));
}

/** The label of each segment keyed by the id of the cut that starts it (null: the first). */
export function labelsByStartCut(review: Review): Map<number | null, string | null> {
  const kept = sortedCuts(review.cuts);
  const map = new Map<number | null, string | null>();
  for (const s of review.segments) map.set(s.index === 0 ? null : (kept[s.index - 1]?.id ?? NaN), s.label);
  return map;
}

export function segmentAt(segments: readonly Segment[], frame: number): Segment | undefined {
  return segments.find((s) => s.start <= frame && frame < s.stop) ?? segments[segments.length - 1];
}

/** The nearest visible cut strictly before (`direction` -1) or after (+1) `frame`. */
export function neighbourCut(cuts: readonly Cut[], frame: number, direction: -1 | 1): Cut | undefined {
  const sorted = sortedCuts(cuts);
  if (direction > 0) return sorted.find((c) => c.frame > frame);
  return [...sorted].reverse().find((c) => c.frame < frame);
}

/** The nearest pending candidate strictly before (-1) or after (+1) `frame`. */
export function neighbourPending(cuts: readonly Cut[], frame: number, direction: -1 | 1): Cut | undefined {
  return neighbourCut(cuts.filter((c) => c.fate === "pending"), frame, direction);
}

/** The nearest unlabelled segment starting strictly before (-1) or after (+1) `frame`. */
export function neighbourUnlabelled(segments: readonly Segment[], frame: number, direction: -1 | 1): Segment | undefined {
  const open = segments.filter((s) => !s.label);
  if (direction > 0) return open.find((s) => s.start > frame);
  return [...open].reverse().find((s) => s.start < frame);
}

/** The deleted candidate nearest `frame` (either side; the earlier one on a tie). */
export function nearestDeleted(cuts: readonly Cut[], frame: number): Cut | undefined {
  const deleted = cuts.filter((c) => c.fate === "deleted" && c.origin === "candidate");
  return deleted.sort((a, b) => Math.abs(a.frame - frame) - Math.abs(b.frame - frame) || a.frame - b.frame)[0];
}

/**
 * An unstarted review (id null: reading never creates one) with temporary negative ids
 * on its candidate cuts, so they can be selected and edited before the first save
 * starts the review.
 */
export function withTempIds(review: Omit<ApiReview, "segments"> & { segments: Segment[] }): Review {
  // A started review's cuts all have ids; an unstarted one's have none.
  return { ...review, cuts: review.cuts.map((c, i) => ({ ...c, id: c.id ?? -1 - i })) };
}

/** Temporary ids of an unstarted review's candidates -> the started review's cut ids (by candidate frame). */
export function startedIds(unstarted: Review, started: Review): Map<number, number> {
  const byFrame = new Map(started.cuts.filter((c) => c.origin === "candidate").map((c) => [c.candidate_frame, c.id]));
  const ids = new Map<number, number>();
  for (const cut of unstarted.cuts) {
    const id = byFrame.get(cut.candidate_frame);
    if (cut.id < 0 && id !== undefined) ids.set(cut.id, id);
  }
  return ids;
}

/** Predict the server's answer to `edit`; throws `EditError` for an edit it would refuse. */
export function applyEdit(review: Review, edit: Edit, nFrames: number): Review {
  if (isServerEdit(edit)) return review;
  const cuts = review.cuts.map((c) => ({ ...c }));
  if (edit.kind === "label") {
    const segments = review.segments.map((s) =>
      s.start === edit.start && s.stop === edit.stop ? { ...s, label: edit.label } : s,
    );
    if (!review.segments.some((s) => s.start === edit.start && s.stop === edit.stop)) {
      throw new EditError(`No segment ${edit.start}–${edit.stop} to label.`);
    }
    return { ...review, segments };
  }
  if (edit.kind === "attribute") {
    const found = review.segments.some((s) => s.start === edit.start && s.stop === edit.stop);
    if (!found) throw new EditError(`No segment ${edit.start}–${edit.stop} to set ${edit.name} on.`);
    return { ...review, segments: review.segments.map((s) => (s.start === edit.start && s.stop === edit.stop ? { ...s, attributes: withValue(s.attributes, edit.name, edit.value) } : s)) };
  }
  if (edit.kind === "insert") {
    checkInsert(review.cuts, edit.frame, nFrames);
    cuts.push({ id: edit.tempId, origin: "inserted", fate: "accepted", candidate_frame: null, frame: edit.frame, confidence: null });
  } else {
    const cut = cuts.find((c) => c.id === edit.cutId);
    if (!cut) throw new EditError(`Cut ${edit.cutId} is not in this review.`);
    if (edit.kind === "fate") restoreOrSetFate(cut, cuts, edit.fate);
    else moveCut(cut, cuts, edit.frame, nFrames);
  }
  const labels = labelsByStartCut(review);
  const segments = deriveSegments(cuts, nFrames, (id) => labels.get(id) ?? null);
  return { ...review, cuts, segments: withAttributes(review, cuts, segments) };
}

/** `segments` (derived after a cut edit) with the attribute values of the segment that
 * started at the same cut before it, as the server keys them. */
function withAttributes(review: Review, cuts: readonly Cut[], segments: Segment[]): Segment[] {
  const startCut = (kept: Cut[], index: number) => (index === 0 ? null : (kept[index - 1]?.id ?? NaN));
  const before = sortedCuts(review.cuts);
  const byCut = new Map<number | null, Segment["attributes"]>();
  for (const s of review.segments) if (s.attributes) byCut.set(startCut(before, s.index), s.attributes);
  if (!byCut.size) return segments;
  const after = sortedCuts(cuts);
  return segments.map((s) => ({ ...s, attributes: byCut.get(startCut(after, s.index)) ?? {} }));
}

function withValue(values: AttributeValues | undefined, name: string, value: string | boolean | null): AttributeValues {
  const next: AttributeValues = { ...(values ?? {}) };
  if (value === null) delete next[name];
  else next[name] = value;
  return next;
}

function checkInsert(cuts: readonly Cut[], frame: number, nFrames: number): void {
  if (!Number.isInteger(frame) || frame <= 0 || frame >= nFrames) {
    throw new EditError(`A cut must lie inside the take (1–${nFrames - 1}), not at frame ${frame}.`);
  }
  if (cuts.some((c) => isKept(c) && c.frame === frame)) {
    throw new EditError(`There is already a cut at frame ${frame}.`);
  }
}

function restoreOrSetFate(cut: Cut, cuts: readonly Cut[], fate: Cut["fate"]): void {
  if (cut.fate === "deleted" && fate !== "deleted" && cuts.some((c) => c.id !== cut.id && isKept(c) && c.frame === cut.frame)) {
    throw new EditError(`Cannot restore the cut at frame ${cut.frame}: another cut is there now.`);
  }
  cut.fate = fate;
}

function moveCut(cut: Cut, cuts: readonly Cut[], frame: number, nFrames: number): void {
  if (cut.fate === "deleted") throw new EditError(`Cut at frame ${cut.frame} is deleted; restore it before moving it.`);
  if (!Number.isInteger(frame) || frame <= 0 || frame >= nFrames) {
    throw new EditError(`A cut must lie inside the take (1–${nFrames - 1}), not at frame ${frame}.`);
  }
  if (cuts.some((c) => c.id !== cut.id && isKept(c) && c.frame === frame)) {
    throw new EditError(`There is already a cut at frame ${frame}.`);
  }
  cut.frame = frame;
  // The server calls a moved candidate "moved"; an inserted cut stays "accepted".
  cut.fate = movedFate(cut);
}

export function movedFate(cut: Pick<Cut, "origin">): Fate {
  return cut.origin === "candidate" ? "moved" : "accepted";
}

export interface Request {
  method: "POST" | "PATCH";
  url: string;
  body: Record<string, unknown>;
}

/**
 * The API call for `edit` (docs/api.md, "Reviews"); `resolveId` maps local ids to server
 * ids, `reviewId` is the started review's id (a restore names it).
 */
export function editRequest(captureId: number, edit: Edit, version: number, resolveId: (id: number) => number, reviewId: number | null = null): Request {
  const base = `/api/captures/${captureId}/review`;
  switch (edit.kind) {
    case "undo":
    case "redo":
      return { method: "POST", url: `${base}/${edit.kind}/`, body: { version } };
    case "restore":
      return { method: "POST", url: `/api/captures/${captureId}/reviews/${reviewId}/restore/`, body: { event: edit.event, version } };
    case "insert":
      return { method: "POST", url: `${base}/cuts/`, body: { frame: edit.frame, version } };
    case "fate":
      return { method: "PATCH", url: `${base}/cuts/${resolveId(edit.cutId)}/`, body: { fate: edit.fate, version } };
    case "move":
      return { method: "PATCH", url: `${base}/cuts/${resolveId(edit.cutId)}/`, body: { frame: edit.frame, version } };
    case "label":
    case "attribute":
      throw new EditError("A segment edit needs the segment index: use labelRequest.");
  }
}

/** Label requests name the segment by its index in the review the server holds now. */
export function labelRequest(captureId: number, review: Review, edit: Extract<Edit, { kind: "label" | "attribute" }>, version: number): Request {
  const segment = review.segments.find((s) => s.start === edit.start && s.stop === edit.stop);
  if (!segment) throw new EditError(`Segment ${edit.start}–${edit.stop} no longer exists.`);
  if (edit.kind === "attribute") {
    const url = `/api/captures/${captureId}/review/segments/${segment.index}/attributes/`;
    return { method: "PATCH", url, body: { name: edit.name, value: edit.value, version } };
  }
  return {
    method: "PATCH",
    url: `/api/captures/${captureId}/review/segments/${segment.index}/`,
    body: { label: edit.label, version },
  };
}

/** The id the server gave to a cut we inserted: the one new kept cut at that frame. */
export function findInsertedId(before: Review, after: Review, frame: number): number | undefined {
  const known = new Set(before.cuts.map((c) => c.id));
  return after.cuts.find((c) => !known.has(c.id) && c.frame === frame)?.id;
}

export const FATE_TEXT: Record<Fate, string> = {
  pending: "candidate",
  accepted: "accepted",
  moved: "moved",
  deleted: "deleted",
};

/** What differs between the review we showed and the server's current one, in words. */
export function describeDifferences(mine: Review, theirs: Review): string[] {
  const lines: string[] = [];
  const theirCuts = new Map(theirs.cuts.map((c) => [c.id, c]));
  const myCuts = new Map(mine.cuts.map((c) => [c.id, c]));
  for (const cut of theirs.cuts) {
    const old = myCuts.get(cut.id);
    if (!old) lines.push(`cut at frame ${cut.frame} was added (${FATE_TEXT[cut.fate]})`);
    else if (old.frame !== cut.frame) lines.push(`cut at frame ${old.frame} is now at frame ${cut.frame}`);
    else if (old.fate !== cut.fate) lines.push(`cut at frame ${cut.frame} is ${FATE_TEXT[cut.fate]}, not ${FATE_TEXT[old.fate]}`);
  }
  for (const cut of mine.cuts) {
    if (!theirCuts.has(cut.id) && cut.id > 0) lines.push(`cut at frame ${cut.frame} no longer exists`);
  }
  for (const s of theirs.segments) {
    const old = mine.segments.find((o) => o.start === s.start && o.stop === s.stop);
    if (old && old.label !== s.label) lines.push(`segment ${s.start}–${s.stop} is labelled ${s.label ?? "nothing"}, not ${old.label ?? "nothing"}`);
  }
  if (mine.status !== theirs.status) lines.push(`the review is now ${theirs.status.replace("_", " ")}`);
  return lines;
}
