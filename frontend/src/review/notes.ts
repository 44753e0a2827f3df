// The review page's comments and segment attributes: the side panels that list the
// comments the caller reads (threads with replies, each jumpable) and the attributes of
// the segment under the playhead, and the keys that add a comment (C), jump between
// comments (M / Shift+M) and set an attribute (its letter).

import { api, get, patch, post } from "../api/client";
import type { AttributeValues, ReviewComment, Segment, SegmentAttribute } from "../api/types";
import { clear, h, toast } from "../ui/dom";
import { promptDialog, promptLine } from "../ui/prompt";
import type { ReviewSession } from "./session";

export interface NotesContext {
  session: ReviewSession;
  captureId: number;
  /** The playhead's frame. */
  frame(): number;
  /** Move the playhead to `frame` (paused) and show it. */
  goTo(frame: number): void;
  refresh(): void;
}

/** The comment threads in frame order (ties: oldest first), replies left out. */
export function threadsInOrder(comments: readonly ReviewComment[]): ReviewComment[] {
  return comments.filter((c) => c.parent === null).sort((a, b) => a.frame - b.frame || a.id - b.id);
}

/** The thread strictly after (+1) or before (-1) `frame`. */
export function neighbourComment(comments: readonly ReviewComment[], frame: number, direction: -1 | 1): ReviewComment | undefined {
  const threads = threadsInOrder(comments);
  return direction > 0 ? threads.find((c) => c.frame > frame) : [...threads].reverse().find((c) => c.frame < frame);
}

/** The value an attribute's key gives next: the next option (Shift: the previous one; past
 * the last, none), yes/no toggled. Free text is asked for. */
export function nextValue(attribute: SegmentAttribute, current: unknown, back = false): string | boolean | null {
  if (attribute.kind === "boolean") return current !== true;
  const options = attribute.options ?? [];
  const cycle: (string | null)[] = [...options, null];
  const at = cycle.indexOf(typeof current === "string" ? current : null);
  return cycle[(at + (back ? cycle.length - 1 : 1)) % cycle.length];
}

export class Notes {
  comments: ReviewComment[] = [];
  attributes: SegmentAttribute[] = [];

  constructor(private readonly ctx: NotesContext) {}

  async load(projectId: number | null): Promise<void> {
    const [comments, attributes] = await Promise.all([
      get<ReviewComment[]>(`/api/captures/${this.ctx.captureId}/comments/`).catch(() => []),
      projectId ? get<SegmentAttribute[]>(`/api/projects/${projectId}/attributes/`).catch(() => []) : Promise.resolve([]),
    ]);
    this.comments = comments;
    this.attributes = attributes;
    this.ctx.refresh();
  }

  // ---- keys ----------------------------------------------------------------------------

  /** The letters the project's attributes answer to. */
  hotkeys(): string {
    return this.attributes.map((a) => a.hotkey ?? "").join("");
  }

  jump(direction: -1 | 1): void {
    const frame = this.ctx.frame();
    const next = neighbourComment(this.comments, frame, direction);
    if (!next) return toast(`No comment ${direction > 0 ? "after" : "before"} frame ${frame}.`);
    this.ctx.goTo(next.frame);
  }

  /** A new thread on `segment` when given, else on the selected cut, else at the playhead. */
  async add(segment?: Segment): Promise<void> {
    const s = this.ctx.session;
    const cut = segment ? undefined : s.selectedCut();
    const frame = this.ctx.frame();
    const where = segment ? `segment ${segment.start}–${segment.stop - 1}` : cut && cut.id > 0 ? `the cut at frame ${cut.frame}` : `frame ${frame}`;
    const text = await promptDialog(`Comment on ${where}`, s.readOnly ? `On ${s.review.annotator.username}'s review: they and the project's reviewers read it.` : "The project's reviewers and admins read it; other annotators do not.", "Comment");
    if (!text) return;
    const anchor = segment ? { segment: segment.index } : cut && cut.id > 0 ? { cut: cut.id } : { frame };
    await this.send(s.review.id === null ? `/api/captures/${this.ctx.captureId}/review/comments/` : this.url(s.review.id), { text, ...anchor }, "Comment added.");
  }

  private async reply(thread: ReviewComment): Promise<void> {
    const text = await promptDialog("Reply", `To “${thread.text.slice(0, 80)}”`, "Reply");
    if (text) await this.send(this.url(thread.review), { text, parent: thread.id }, "Reply added.");
  }

  private async resolve(thread: ReviewComment): Promise<void> {
    try {
      await patch(`${this.url(thread.review)}${thread.id}/`, { resolved: !thread.resolved });
      await this.reload();
    } catch (err) {
      toast((err as Error).message, "error");
    }
  }

  private url(reviewId: number): string {
    return `/api/captures/${this.ctx.captureId}/reviews/${reviewId}/comments/`;
  }

  private async send(url: string, body: object, done: string): Promise<void> {
    try {
      await post(url, body);
      toast(done);
      await this.reload();
    } catch (err) {
      toast(`Not saved: ${(err as Error).message}`, "error");
    }
  }

  private async reload(): Promise<void> {
    this.comments = await api<ReviewComment[]>("GET", `/api/captures/${this.ctx.captureId}/comments/`);
    this.ctx.refresh();
  }

  /** An attribute's key: set it on the segment under the playhead. */
  async attributeKey(hotkey: string, back: boolean, segment: Segment | undefined): Promise<void> {
    const attribute = this.attributes.find((a) => a.hotkey === hotkey);
    if (attribute) await this.choose(attribute, back, segment);
  }

  private async choose(attribute: SegmentAttribute, back: boolean, segment: Segment | undefined): Promise<void> {
    if (!segment) return toast("No segment under the playhead.");
    const current = segment.attributes?.[attribute.name];
    if (attribute.kind !== "text") return this.set(segment, attribute, nextValue(attribute, current, back));
    const text = await promptLine(attribute.name, `The ${attribute.name} of segment ${segment.start}–${segment.stop - 1} (a single - clears it).`, "Set", typeof current === "string" ? current : "");
    if (text !== null) this.set(segment, attribute, text.trim() === "-" ? null : text.trim());
  }

  private set(segment: Segment, attribute: SegmentAttribute, value: string | boolean | null): void {
    if (this.ctx.session.perform({ kind: "attribute", start: segment.start, stop: segment.stop, name: attribute.name, value })) {
      toast(`${attribute.name}: ${value === null ? "cleared" : value === true ? "yes" : value === false ? "no" : value}`);
    }
  }

  // ---- panels --------------------------------------------------------------------------

  render(commentsEl: HTMLElement, attributesEl: HTMLElement, section: HTMLElement, segment: Segment | undefined): void {
    this.renderComments(commentsEl);
    section.hidden = this.attributes.length === 0;
    if (this.attributes.length) this.renderAttributes(attributesEl, segment);
  }

  private renderComments(el: HTMLElement): void {
    const threads = threadsInOrder(this.comments);
    const shown = this.ctx.session.review.id;
    if (!threads.length) {
      clear(el, h("p", { class: "muted" }, "No comments. C comments at the playhead; M / Shift+M jump between comments."));
      return;
    }
    const item = (c: ReviewComment, reply: boolean) =>
      h("div", { class: reply ? "comment reply" : "comment", "data-testid": reply ? "comment-reply" : "comment" },
        h("span", { class: "muted" }, `${c.author ?? "—"}${reply ? "" : ` · frame ${c.frame}${c.anchor === "frame" ? "" : ` (${c.anchor})`}`}${c.review !== shown ? ` · on ${c.annotator}'s review` : ""}`),
        h("div", { class: "comment-text" }, c.text));
    clear(el, ...threads.map((t) =>
      h("div", { class: t.resolved ? "thread resolved" : "thread", "data-testid": `thread-${t.frame}` },
        h("button", { class: "btn btn-small link", title: "Go to its frame", "data-testid": "comment-go", onclick: () => this.ctx.goTo(t.frame) }, "⤳"),
        item(t, false),
        ...this.comments.filter((c) => c.parent === t.id).map((c) => item(c, true)),
        h("div", { class: "thread-actions" },
          h("button", { class: "btn btn-small", "data-testid": "comment-reply-button", onclick: () => void this.reply(t) }, "Reply"),
          h("button", { class: "btn btn-small", "data-testid": "comment-resolve", onclick: () => void this.resolve(t) }, t.resolved ? "Reopen" : "Resolve")))));
  }

  private renderAttributes(el: HTMLElement, segment: Segment | undefined): void {
    const values: AttributeValues = segment?.attributes ?? {};
    const locked = this.ctx.session.locked() !== null;
    const key = (a: SegmentAttribute) => (a.hotkey ? ` (${a.hotkey.toUpperCase()})` : "");
    clear(el, ...this.attributes.map((a) => {
      const value = values[a.name];
      let control: HTMLElement;
      if (a.kind === "boolean") {
        control = h("button", { class: value === true ? "btn btn-small active" : "btn btn-small", disabled: locked || !segment, "data-testid": `attribute-${a.name}`, onclick: (e: Event) => { (e.currentTarget as HTMLElement).blur(); if (segment) this.set(segment, a, value !== true); } }, value === true ? "yes" : "no");
      } else if (a.kind === "choice") {
        control = h("span", {}, ...(a.options ?? []).map((o) =>
          h("button", { class: value === o ? "btn btn-small active" : "btn btn-small", disabled: locked || !segment, "data-testid": `attribute-${a.name}-${o}`, onclick: (e: Event) => { (e.currentTarget as HTMLElement).blur(); if (segment) this.set(segment, a, value === o ? null : o); } }, o)));
      } else {
        control = h("button", { class: "btn btn-small", disabled: locked || !segment, "data-testid": `attribute-${a.name}`, onclick: (e: Event) => { (e.currentTarget as HTMLElement).blur(); void this.choose(a, false, segment); } }, typeof value === "string" ? value : "—");
      }
      return h("div", { class: "attribute-row" }, h("span", { class: "muted" }, `${a.name}${key(a)}`), control);
    }));
  }
}
