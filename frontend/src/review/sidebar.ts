// The review page's side: labels of the segment under the playhead, the selection, the
// review's counts, the activity log and, for reviewers, the other annotators' reviews.

import { get, post } from "../api/client";
import type { Adaptation, Label, Me, Project, ReadyCapture, Review, ReviewEvent, Segment } from "../api/types";
import { returnReview } from "../queue/api";
import { clear, confirmDialog, h, toast } from "../ui/dom";
import { promptDialog } from "../ui/prompt";
import { eventDetail } from "./events";
import type { Elements } from "./layout";
import { renderAdaptation, renderEvents, renderLabels, renderSelection, renderStats } from "./panels";
import type { ReviewSession } from "./session";

export interface SidebarActions {
  /** Label the segment under the playhead. */
  label(name: string): void;
  /** Show another annotator's review read-only, or the own one (null). */
  show(other: Review | null): void;
}

export class Sidebar {
  /** The segment the panels describe: they are redrawn when the playhead leaves it. */
  shownSegment: Segment | undefined;

  constructor(
    private readonly el: Elements,
    private readonly capture: ReadyCapture,
    private readonly labels: Label[],
    private readonly adaptation: Adaptation,
    private readonly actions: SidebarActions,
  ) {}

  render(session: ReviewSession, segment: Segment | undefined): void {
    this.shownSegment = segment;
    renderLabels(this.el.labels, this.labels, segment?.label ?? null, session.locked() !== null, this.actions.label,
      segment?.suggested_label ?? null);
    renderSelection(this.el.selection, session.selectedCut(), segment, this.capture.fps);
    renderStats(this.el.stats, session.review);
    renderAdaptation(this.el.adaptation, this.adaptation);
  }

  /** The own review's activity log, each entry offering `restore` when given. */
  async loadEvents(restore?: (e: ReviewEvent) => void): Promise<ReviewEvent[] | null> {
    const events = await get<ReviewEvent[] | { results: ReviewEvent[] }>(`/api/captures/${this.capture.id}/review/events/`).catch(() => null);
    if (!events) return null;
    const list = listOf(events);
    renderEvents(this.el.events, list, restore);
    return list;
  }

  /** Reviewers and admins pick whose review to show; a submitted one can be returned. */
  async loadOtherReviews(project: Project | null, me: Me): Promise<void> {
    if (!project || project.role === "annotator") return;
    const reviews = await get<Review[] | { results: Review[] }>(`/api/captures/${this.capture.id}/reviews/`).catch(() => null);
    if (!reviews) return;
    const others = listOf(reviews).filter((r) => r.annotator.id !== me.id);
    if (!others.length) return;
    const select = h(
      "select",
      { class: "select", "data-testid": "review-picker", title: "Whose review to show" },
      h("option", { value: "" }, "My review"),
      ...others.map((r) => h("option", { value: String(r.id) }, `${r.annotator.username} (read-only)`)),
    );
    const giveBack = h("button", { class: "btn", hidden: true, "data-testid": "return-review", title: "Send this submitted review back to its annotator with a comment", onclick: () => void this.giveBack(others, select, project, me) }, "Return…");
    select.addEventListener("change", () => {
      select.blur();
      const other = others.find((r) => String(r.id) === select.value);
      this.el.eventsTitle.textContent = other ? `Activity of ${other.annotator.username}'s review` : "Activity";
      giveBack.hidden = other?.status !== "submitted";
      this.actions.show(other ?? null);
      if (other) void this.loadOthersEvents(other, others);
    });
    clear(this.el.reviewPicker, select, giveBack);
  }

  /** Another annotator's log; a reviewer may restore their review (not once submitted). */
  private async loadOthersEvents(review: Review, others: Review[]): Promise<void> {
    const events = await get<ReviewEvent[] | { results: ReviewEvent[] }>(`/api/captures/${this.capture.id}/reviews/${review.id}/events/`).catch(() => null);
    if (!events) return;
    const restore = review.status === "submitted" ? undefined : (e: ReviewEvent) => void this.restoreOthers(review, e, others);
    renderEvents(this.el.events, listOf(events), restore);
  }

  private async restoreOthers(review: Review, e: ReviewEvent, others: Review[]): Promise<void> {
    if (!(await confirmRestore(e, `${review.annotator.username}'s review`))) return;
    try {
      const restored = await post<Review>(`/api/captures/${this.capture.id}/reviews/${review.id}/restore/`, { event: e.id, version: review.version });
      others[others.indexOf(review)] = restored;
      toast(`Restored ${review.annotator.username}'s review.`);
      this.actions.show(restored);
      await this.loadOthersEvents(restored, others);
    } catch (err) {
      toast((err as Error).message, "error");
    }
  }

  private async giveBack(others: Review[], select: HTMLSelectElement, project: Project, me: Me): Promise<void> {
    const review = others.find((r) => String(r.id) === select.value);
    if (!review) return;
    const comment = await promptDialog(`Return ${review.annotator.username}'s review`, "Say what should change; they see it in their queue, edit and resubmit. Until then the review leaves agreement and the library.", "Return");
    if (!comment) return;
    try {
      await returnReview(this.capture.id, review.id as number, comment);
      toast(`Returned to ${review.annotator.username}.`);
      select.value = "";
      select.dispatchEvent(new Event("change"));
      clear(this.el.reviewPicker);
      void this.loadOtherReviews(project, me);
    } catch (err) {
      toast((err as Error).message, "error");
    }
  }
}

/** Ask before restoring `whose` review as it was right after the log entry `e`. */
export function confirmRestore(e: ReviewEvent, whose = "The review"): Promise<boolean> {
  const what = `${e.action} ${eventDetail(e)}`.trim();
  return confirmDialog("Restore this point of the activity?", [
    h("p", {}, `${whose} goes back to how it was right after “${what}” (${new Date(e.created_at).toLocaleTimeString()}).`),
    h("p", { class: "muted" }, "The restore is itself an entry of the activity log: undo (Z) takes it back."),
  ], "Restore");
}

export function listOf<T>(value: T[] | { results: T[] }): T[] {
  return Array.isArray(value) ? value : value.results;
}
