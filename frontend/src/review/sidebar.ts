// The review page's side: labels of the segment under the playhead, the selection, the
// review's counts, the activity log and, for reviewers, the other annotators' reviews.

import { get } from "../api/client";
import type { Adaptation, Label, Me, Project, ReadyCapture, Review, ReviewEvent, Segment } from "../api/types";
import { returnReview } from "../queue/api";
import { clear, h, toast } from "../ui/dom";
import { promptDialog } from "../ui/prompt";
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
    renderLabels(this.el.labels, this.labels, segment?.label ?? null, session.locked() !== null, this.actions.label);
    renderSelection(this.el.selection, session.selectedCut(), segment, this.capture.fps);
    renderStats(this.el.stats, session.review);
    renderAdaptation(this.el.adaptation, this.adaptation);
  }

  /** The own review's activity log (the log of a review shown read-only is not fetched). */
  async loadEvents(): Promise<ReviewEvent[] | null> {
    const events = await get<ReviewEvent[] | { results: ReviewEvent[] }>(`/api/captures/${this.capture.id}/review/events/`).catch(() => null);
    if (!events) return null;
    const list = listOf(events);
    renderEvents(this.el.events, list);
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
      this.el.eventsTitle.textContent = select.value ? "Activity (of your own review)" : "Activity";
      const other = others.find((r) => String(r.id) === select.value);
      giveBack.hidden = other?.status !== "submitted";
      this.actions.show(other ?? null);
    });
    clear(this.el.reviewPicker, select, giveBack);
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

export function listOf<T>(value: T[] | { results: T[] }): T[] {
  return Array.isArray(value) ? value : value.results;
}
