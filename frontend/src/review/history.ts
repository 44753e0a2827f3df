// Undo/redo as the server keeps them. The review's audit log is its history: an edit (or a
// restore from the activity log) is a step; undo and redo are restores the server makes
// (POST …/review/undo/, …/redo/), logged with their intent, so the stacks read from the
// log after a reload are the ones the page had (segmentation/services/history.py reads
// them the same way). Between two reads of the log the page keeps the stacks itself:
// only step titles, for the buttons and the toasts.

import type { Review, ReviewEvent } from "../api/types";
import { eventDetail } from "./events";
import { EditError, type Edit } from "./state";

export interface History {
  /** Titles of the steps undo would take back, the next one last. */
  past: string[];
  /** Titles of the undone steps redo would make again, the next one last. */
  future: string[];
}

/** Events that change cuts or labels: the steps of the history. */
const STEP_ACTIONS = new Set(["insert", "accept", "delete", "reset", "move", "label", "restore", "import"]);

export const emptyHistory = (): History => ({ past: [], future: [] });

export function record(history: History, title: string, limit = 500): History {
  return { past: [...history.past, title].slice(-limit), future: [] };
}

/** The history after an undo (`which` "undo") or a redo, with the title of that step. */
export function stepped(history: History, which: "undo" | "redo"): { history: History; title: string } | null {
  const [from, to] = which === "undo" ? [history.past, history.future] : [history.future, history.past];
  const title = from[from.length - 1];
  if (title === undefined) return null;
  const moved = { from: from.slice(0, -1), to: [...to, title] };
  return { history: which === "undo" ? { past: moved.from, future: moved.to } : { past: moved.to, future: moved.from }, title };
}

/** The undo and redo stacks as the review's log (oldest event first) leaves them. */
export function historyFromEvents(events: readonly ReviewEvent[]): History {
  let history = emptyHistory();
  for (const e of events) {
    const intent = e.action === "restore" ? ((e.after ?? {}) as { intent?: string | null }).intent ?? null : null;
    if (intent === "undo" || intent === "redo") history = stepped(history, intent)?.history ?? history;
    else if (STEP_ACTIONS.has(e.action)) history = record(history, eventTitle(e));
  }
  return history;
}

function eventTitle(e: ReviewEvent): string {
  const detail = eventDetail(e);
  return detail ? `${e.action} ${detail}` : e.action;
}

/** What `edit` does in words, measured on the review before it is applied. */
export function editTitle(review: Review, edit: Edit): string {
  if (edit.kind === "label") return edit.label ? `label ${edit.label}` : "clear label";
  if (edit.kind === "attribute") return edit.value === null ? `clear ${edit.name}` : `${edit.name}: ${String(edit.value)}`;
  if (edit.kind === "insert") return `insert cut at ${edit.frame}`;
  if (edit.kind === "undo" || edit.kind === "redo") return edit.kind;
  if (edit.kind === "restore") return "restore an earlier point";
  const cut = review.cuts.find((c) => c.id === edit.cutId);
  if (!cut) throw new EditError(`Cut ${edit.cutId} is not in this review.`);
  if (edit.kind === "move") return `move cut ${cut.frame} → ${edit.frame}`;
  const verb = { accepted: "accept", deleted: "delete", pending: cut.fate === "deleted" ? "restore" : "reset" }[edit.fate];
  return `${verb} cut at ${cut.frame}`;
}
