// The review page's dialogs: a conflict explained, a submit confirmed with what it keeps,
// and where "Submit & next" goes.

import type { ReadyCapture, Review } from "../api/types";
import { nextInQueue } from "../queue/api";
import { navigate } from "../router";
import { confirmDialog, dialog, h, toast } from "../ui/dom";

/** The review changed elsewhere: what changed, and which of the caller's edits were not saved. */
export function showConflict(changes: string[], unsaved: string[]): Promise<void> {
  // The server's text is for API clients (it names the review and says to reload); the
  // page has already loaded the current version, so it says that instead.
  return dialog("This review changed elsewhere", [
    h("p", { "data-testid": "conflict-text" }, "Your review was saved from another tab or window first. This page shows that version now."),
    h("p", {}, "What changed:"),
    h("ul", { "data-testid": "conflict-changes" }, ...(changes.length ? changes : ["(nothing visible)"]).map((line) => h("li", {}, line))),
    unsaved.length ? h("p", {}, "Not saved — redo these if you still want them:") : null,
    unsaved.length ? h("ul", { "data-testid": "conflict-unsaved" }, ...unsaved.map((t) => h("li", {}, t))) : null,
  ]);
}

/** Ask before submitting, saying how many pending candidates it keeps as cuts and how many
 * proposed labels (``proposed``: unlabelled segments with a suggestion) stay unconfirmed. */
export function confirmSubmit(review: Review, next: boolean, proposed = 0): Promise<boolean> {
  const pending = review.cuts.filter((c) => c.fate === "pending").length;
  const unlabelled = review.segments.filter((seg) => !seg.label).length;
  // Submitting keeps every cut not deleted, pending candidates included: say so, with the count.
  const candidates = `${pending} pending candidate${pending === 1 ? "" : "s"}`;
  return confirmDialog(next ? "Submit and open the next capture?" : "Submit this review?", [
    h("p", {}, "A submitted review counts towards agreement and the library, and can no longer be edited."),
    pending
      ? h("p", { "data-testid": "submit-pending" }, h("strong", {}, `${candidates} will be kept as cuts.`), ` Accept or delete ${pending === 1 ? "it" : "them"} first to decide each one.`)
      : null,
    proposed ? h("p", { "data-testid": "submit-proposed" }, `${proposed} proposed label${proposed === 1 ? " is" : "s are"} not confirmed and will not be saved (press S on a segment to accept its proposal).`) : null,
    unlabelled ? h("p", { class: "muted", "data-testid": "submit-unlabelled" }, `${unlabelled} unlabelled segment${unlabelled === 1 ? "" : "s"} will be left out of the library.`) : null,
  ], pending ? `Submit, keeping ${pending}` : "Submit");
}

/** The oldest open capture of the caller's queue in this project, or the queue itself. */
export async function openNext(capture: ReadyCapture): Promise<void> {
  const item = await nextInQueue(capture.project, capture.id).catch(() => null);
  if (item) navigate(`/captures/${item.capture.id}/`);
  else {
    toast("Your queue has nothing else open.");
    navigate(`/queue/?project=${capture.project}`);
  }
}
