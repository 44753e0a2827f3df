// The review being edited, without any DOM: the review as shown, the selected cut, the
// undo history, the saver and what happens on a save, a conflict or a failure. The page
// draws what this holds and forwards gestures and keys to it; unit tests drive it alone.

import { api } from "../api/client";
import type { Cut, Review, ReviewEvent } from "../api/types";
import { editTitle, emptyHistory, historyFromEvents, record, stepped, type History } from "./history";
import { Saver, type Send } from "./saver";
import { applyEdit, describeDifferences, EditError, segmentAt, type Edit } from "./state";

/** What the session tells the page: it draws, speaks and asks, the session decides. */
export interface SessionView {
  /** The review, the selection or the history changed: redraw. */
  changed(): void;
  notice(text: string, error?: boolean): void;
  /** How many edits wait to be saved (0: everything is saved). */
  saving(pending: number): void;
  /** Every queued edit is saved: the server's review is shown now. */
  settled(review: Review): void;
  /** The server refused an edit as stale: its review is shown now. */
  conflict(changes: string[], unsaved: string[]): void;
}

export class ReviewSession {
  review: Review;
  history: History = emptyHistory();
  selectedCutId: number | null = null;
  /** Another annotator's review, shown read-only (reviewers), or null for the own one. */
  private other: Review | null = null;
  private pushes = 0;
  private nextTempId: number;
  private own: Review;
  readonly saver: Saver;

  constructor(
    readonly captureId: number,
    readonly nFrames: number,
    review: Review,
    private readonly view: SessionView,
    private readonly send: Send = api,
  ) {
    this.review = this.own = review;
    // Below the temporary ids an unstarted review's candidates carry.
    this.nextTempId = Math.min(0, ...review.cuts.map((c) => c.id)) - 1;
    this.saver = new Saver(captureId, review, {
      saved: (r, idle, renamed) => this.onSaved(r, idle, renamed),
      conflict: (r, unsaved) => this.onConflict(r, unsaved),
      failed: (r, unsaved, message) => this.onFailed(r, unsaved, message),
      busy: (n) => view.saving(n),
    }, send);
  }

  get readOnly(): boolean {
    return this.other !== null;
  }

  /** Why this review cannot be edited now, or null if it can. */
  locked(): string | null {
    if (this.other) return `You are viewing ${this.review.annotator.username}'s review, read-only.`;
    if (this.review.status === "submitted") return "This review was submitted; it is read-only now.";
    return null;
  }

  /** The selected cut, unless it was deleted meanwhile. */
  selectedCut(): Cut | undefined {
    return this.review.cuts.find((c) => c.id === this.selectedCutId && c.fate !== "deleted");
  }

  select(id: number | null): void {
    this.selectedCutId = id;
    this.view.changed();
  }

  /** Show another annotator's review read-only, or the own one again (null). */
  show(other: Review | null): void {
    this.other = other;
    this.review = other ?? this.saver.server ?? this.own;
    this.selectedCutId = null;
    this.view.changed();
  }

  // ---- edits ---------------------------------------------------------------------------

  /** Apply `edit` on screen at once and queue it for the server; false if refused. */
  perform(edit: Edit): boolean {
    const locked = this.locked();
    if (locked) {
      this.view.notice(locked, true);
      return false;
    }
    try {
      const title = editTitle(this.review, edit);
      this.review = applyEdit(this.review, edit, this.nFrames);
      // An attribute is logged but is no step of the server's undo history.
      if (edit.kind !== "attribute") this.history = record(this.history, title);
      if (edit.kind === "insert") this.selectedCutId = edit.tempId;
      this.saver.push([edit], title);
      this.pushes++;
      return true;
    } catch (err) {
      if (!(err instanceof EditError)) throw err;
      this.view.notice(err.message, true);
      return false;
    } finally {
      this.view.changed();
    }
  }

  insertAt(frame: number): void {
    this.perform({ kind: "insert", frame, tempId: this.nextTempId-- });
  }

  /** Label the segment under `frame` (null clears its label). */
  labelAt(frame: number, label: string | null): void {
    const segment = segmentAt(this.review.segments, frame);
    if (segment) this.perform({ kind: "label", start: segment.start, stop: segment.stop, label });
  }

  /** Accept or delete the selected cut, saying why not when there is none to change. */
  changeSelectedCut(action: "accept" | "delete"): void {
    const cut = this.selectedCut();
    if (!cut) this.view.notice("Select a cut first: click it, or jump to it with Shift+←/→.");
    // Accepting a kept cut would only rewrite its fate (and lose "moved"): say so instead.
    else if (action === "accept" && cut.fate !== "pending") this.view.notice(`The cut at ${cut.frame} is already kept (${cut.origin === "inserted" ? "inserted" : cut.fate}).`);
    else this.perform({ kind: "fate", cutId: cut.id, fate: action === "accept" ? "accepted" : "deleted" });
    if (cut && action === "delete") this.selectedCutId = null;
    this.view.changed();
  }

  /**
   * Undo or redo the last step. The server makes it from the review's log (so it works
   * after a reload too) and answers with the review; the screen shows that answer.
   */
  step(which: "undo" | "redo"): void {
    const locked = this.locked();
    if (locked) return this.view.notice(locked, true);
    const step = stepped(this.history, which);
    if (!step) return this.view.notice(`Nothing to ${which}.`);
    this.history = step.history;
    this.saver.push([{ kind: which }], `${which} ${step.title}`);
    this.pushes++;
    this.view.notice(`${which === "undo" ? "Undo" : "Redo"}: ${step.title}`);
    this.view.changed();
  }

  undo(): void {
    this.step("undo");
  }

  redo(): void {
    this.step("redo");
  }

  /** Restore the review as it was right after its event `event` (an activity log entry). */
  restore(event: number, title: string): void {
    this.perform({ kind: "restore", event });
    this.view.notice(`Restoring the review as it was after “${title}”…`);
  }

  /** How many edits (undo and redo included) this page has sent: a log read while it
   * changes is out of date by the time it arrives. */
  get sent(): number {
    return this.pushes;
  }

  /**
   * The undo/redo stacks as the server's log has them, unless edits are still queued or
   * were sent after the log was asked for (`asOf`: `sent` when it was): a log read before
   * an undo would give that undo's step back.
   */
  readHistory(events: readonly ReviewEvent[], asOf: number = this.pushes): void {
    if (this.saver.pending || this.other || asOf !== this.pushes) return;
    this.history = historyFromEvents(events);
    this.view.changed();
  }

  /** The review as the server changed it outside the edit queue (an import): shown now;
   * the undo history is read from its log again (`settled`). */
  replaced(review: Review): void {
    this.saver.server = this.own = review;
    if (!this.other) this.review = review;
    this.selectedCutId = null;
    this.view.changed();
    this.view.settled(review);
  }

  /** Submit the review as the server holds it; throws the server's refusal. */
  async submit(): Promise<void> {
    this.review = await this.send<Review>("POST", `/api/captures/${this.captureId}/review/submit/`, { version: this.saver.server.version });
    this.saver.server = this.review;
    this.history = emptyHistory();
    this.view.changed();
  }

  // ---- the server's answers ------------------------------------------------------------

  private onSaved(review: Review, idle: boolean, renamed: Map<number, number>): void {
    if (renamed.size) {
      this.review = { ...this.review, cuts: this.review.cuts.map((c) => ({ ...c, id: renamed.get(c.id) ?? c.id })) };
      if (this.selectedCutId !== null) this.selectedCutId = renamed.get(this.selectedCutId) ?? this.selectedCutId;
    }
    if (!idle) return;
    if (!this.other) this.review = review;
    this.view.changed();
    this.view.settled(review);
  }

  private onConflict(current: Review, unsaved: string[]): void {
    const changes = describeDifferences(this.review, current);
    this.review = current;
    this.history = emptyHistory();
    this.view.changed();
    this.view.conflict(changes, unsaved);
  }

  private onFailed(current: Review | null, unsaved: string[], message: string): void {
    if (current) {
      this.review = current;
      this.history = emptyHistory();
    }
    this.view.notice(`Not saved (${unsaved.join(", ")}): ${message}`, true);
    this.view.changed();
  }
}
