// Undo/redo over server-side edits. A history step remembers the state of one cut (or one
// segment's label) before and after; undoing computes, against the review as it is *now*,
// the API edits that bring it back. An inserted cut is "undone" by deleting it and "redone"
// by restoring it, so ids stay stable and no step ever refers to a cut that vanished.

import type { Fate, Review } from "../api/types";
import { EditError, movedFate, type Edit } from "./state";

export interface CutState {
  fate: Fate;
  frame: number;
}

export type Change =
  | { kind: "cut"; title: string; cutId: number; before: CutState; after: CutState }
  | { kind: "label"; title: string; start: number; stop: number; before: string | null; after: string | null };

export interface History {
  past: Change[];
  future: Change[];
}

export const emptyHistory = (): History => ({ past: [], future: [] });

export function record(history: History, change: Change, limit = 500): History {
  return { past: [...history.past, change].slice(-limit), future: [] };
}

/** Describe what `edit` will change, measured on the review before it is applied. */
export function changeFor(review: Review, edit: Edit): Change {
  if (edit.kind === "label") {
    const segment = review.segments.find((s) => s.start === edit.start && s.stop === edit.stop);
    return {
      kind: "label", title: edit.label ? `label ${edit.label}` : "clear label",
      start: edit.start, stop: edit.stop, before: segment?.label ?? null, after: edit.label,
    };
  }
  if (edit.kind === "insert") {
    return {
      kind: "cut", title: `insert cut at ${edit.frame}`, cutId: edit.tempId,
      before: { fate: "deleted", frame: edit.frame }, after: { fate: "accepted", frame: edit.frame },
    };
  }
  const cut = review.cuts.find((c) => c.id === edit.cutId);
  if (!cut) throw new EditError(`Cut ${edit.cutId} is not in this review.`);
  const before = { fate: cut.fate, frame: cut.frame };
  if (edit.kind === "move") {
    return { kind: "cut", title: `move cut ${cut.frame} → ${edit.frame}`, cutId: cut.id, before, after: { fate: movedFate(cut), frame: edit.frame } };
  }
  const verb = { accepted: "accept", deleted: "delete", pending: cut.fate === "deleted" ? "restore" : "reset" }[edit.fate];
  return { kind: "cut", title: `${verb} cut at ${cut.frame}`, cutId: cut.id, before, after: { fate: edit.fate, frame: cut.frame } };
}

/**
 * The API edits that take a cut from `current` to `target`. A move makes the server mark
 * the cut "moved", so a target fate of pending/accepted is set again after moving back;
 * "moved" itself cannot be asked for, only reached by moving.
 */
export function transitionEdits(cutId: number, current: CutState, target: CutState, origin: "candidate" | "inserted" = "candidate"): Edit[] {
  if (target.fate === "deleted") {
    return current.fate === "deleted" ? [] : [{ kind: "fate", cutId, fate: "deleted" }];
  }
  const edits: Edit[] = [];
  let fate = current.fate;
  if (fate === "deleted") {
    fate = target.fate === "moved" ? "accepted" : target.fate;
    edits.push({ kind: "fate", cutId, fate });
  }
  if (current.frame !== target.frame) {
    edits.push({ kind: "move", cutId, frame: target.frame });
    fate = movedFate({ origin });
  }
  if (target.fate !== "moved" && fate !== target.fate) {
    edits.push({ kind: "fate", cutId, fate: target.fate });
  }
  return edits;
}

/** Edits that bring `review` to one side of `change`; throws if the review moved on. */
export function editsToward(review: Review, change: Change, side: "before" | "after", resolveId: (id: number) => number): Edit[] {
  if (change.kind === "label") {
    const segment = review.segments.find((s) => s.start === change.start && s.stop === change.stop);
    if (!segment) throw new EditError(`Segment ${change.start}–${change.stop} no longer exists, so "${change.title}" cannot be reversed.`);
    const label = change[side];
    return segment.label === label ? [] : [{ kind: "label", start: change.start, stop: change.stop, label }];
  }
  const id = resolveId(change.cutId);
  const cut = review.cuts.find((c) => c.id === id);
  if (!cut) throw new EditError(`The cut of "${change.title}" is not in this review any more.`);
  return transitionEdits(cut.id, { fate: cut.fate, frame: cut.frame }, change[side], cut.origin);
}

export function undo(history: History, review: Review, resolveId: (id: number) => number): { history: History; edits: Edit[]; change: Change } | null {
  const change = history.past[history.past.length - 1];
  if (!change) return null;
  const edits = editsToward(review, change, "before", resolveId);
  return { history: { past: history.past.slice(0, -1), future: [...history.future, change] }, edits, change };
}

export function redo(history: History, review: Review, resolveId: (id: number) => number): { history: History; edits: Edit[]; change: Change } | null {
  const change = history.future[history.future.length - 1];
  if (!change) return null;
  const edits = editsToward(review, change, "after", resolveId);
  return { history: { past: [...history.past, change], future: history.future.slice(0, -1) }, edits, change };
}
