// The audit log in words.

import type { ReviewEvent } from "../api/types";

/** One line per audit event: "frame 2088: pending → deleted", "segment 1: — → walk". */
export function eventDetail(e: Pick<ReviewEvent, "action" | "before" | "after">): string {
  const before = (e.before ?? {}) as Record<string, unknown>;
  const after = (e.after ?? {}) as Record<string, unknown>;
  if (e.action === "create") return `${after.candidates ?? 0} candidates`;
  // A review opened before detection finished takes the run's candidates in afterwards.
  if (e.action === "candidates") return `${after.candidates ?? 0} candidates arrived`;
  if (e.action === "restore") return restoreDetail(after);
  // An imported file (services/annotations.py): how many segments, from which file and tier.
  if (e.action === "import") return `${after.segments ?? 0} segments from ${after.file ?? "a file"}${after.source ? ` (${after.source})` : ""}`;
  if (e.action === "attribute") {
    const shown = (v: unknown) => (v === null || v === undefined ? "—" : v === true ? "yes" : v === false ? "no" : String(v));
    return `segment ${Number(after.index ?? before.index) + 1} ${String(after.attribute ?? "")}: ${shown(before.value)} → ${shown(after.value)}`;
  }
  if ("index" in after || "index" in before) {
    const index = Number(after.index ?? before.index);
    return `segment ${index + 1}: ${before.label ?? "—"} → ${after.label ?? "—"}`;
  }
  if (e.action === "insert") return `at frame ${after.frame}`;
  if (before.frame !== undefined && after.frame !== undefined && before.frame !== after.frame) {
    return `frame ${before.frame} → ${after.frame}`;
  }
  if (after.frame !== undefined) return `frame ${after.frame}: ${before.fate ?? "—"} → ${after.fate}`;
  return "";
}

/** "as at 10:42:07 · 3 changes", or for an undo/redo "3 changes". */
function restoreDetail(after: Record<string, unknown>): string {
  const n = ((after.cuts as unknown[] | undefined)?.length ?? 0) + ((after.labels as unknown[] | undefined)?.length ?? 0);
  const changes = `${n} change${n === 1 ? "" : "s"}`;
  if (after.intent || typeof after.at !== "string") return changes;
  return `as at ${new Date(after.at).toLocaleTimeString()} · ${changes}`;
}
