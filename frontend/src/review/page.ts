// The review page: skeleton player on top, timeline lanes under it, labels and the
// activity log at the side. This module only wires the parts together: the review session
// (session.ts: edits, history, saving, conflicts), playback (player/playback.ts), the
// stage (stage.ts), the sidebar (sidebar.ts), the key commands (commands.ts) and the
// timeline (timeline.ts). Every edit is applied on screen at once and saved through the
// API straight away (saver.ts); undo/redo are restores the server makes from the audit
// log (history.ts), so they survive a reload and the log stays complete.

import { ApiError, get } from "../api/client";
import { isReady } from "../api/types";
import type { Adaptation, Capture, Label, Me, OpenedReview, Project, ReadyCapture, Review, ReviewEvent, Signal, SignalResponse } from "../api/types";
import { PlaybackController } from "../player/playback";
import { clear, h, toast } from "../ui/dom";
import { icon } from "../ui/icons";
import { VideoDock } from "../video/dock";
import { Commands } from "./commands";
import { openImportDialog } from "./annotationsDialog";
import { confirmSubmit, openNext, showConflict } from "./dialogs";
import { eventDetail } from "./events";
import { pageCommand } from "./keys";
import type { Command } from "./keymap";
import { buildLayout, type Elements } from "./layout";
import { Notes } from "./notes";
import { ReviewSession } from "./session";
import { confirmRestore, listOf, Sidebar } from "./sidebar";
import { FrameFeed, frameFromUrl, fullSignals, maxJoints, signalsAfterPoses, signalsWait, Stage } from "./stage";
import { segmentAt, withTempIds } from "./state";
import { Suggestions } from "./suggestions";
import { Timeline, type TimelineModel } from "./timeline";

export { frameFromUrl };

export async function renderReview(root: HTMLElement, captureId: number): Promise<() => void> {
  clear(root, h("div", { class: "loading-page" }, "Opening capture…"));
  const [capture, me, projects] = await Promise.all([
    get<Capture>(`/api/captures/${captureId}/`),
    get<Me>("/api/me/"),
    get<Project[] | { results: Project[] }>("/api/projects/"),
  ]);
  const project = listOf(projects).find((p) => p.id === capture.project);
  if (!isReady(capture)) return renderNotReady(root, capture);
  // Poses start streaming now, in parallel with the review and the signal.
  const frames = new FrameFeed(capture, maxJoints(me), !signalsAfterPoses());
  try {
    const [opened, signal] = await Promise.all([
      // Reading does not start a review: the first edit does (saver.ts).
      get<OpenedReview>(`/api/captures/${captureId}/review/`),
      get<SignalResponse>(`/api/captures/${captureId}/signal/?max_points=4000`).catch(() => null),
    ]);
    // Only the page's GET carries the adaptation summary: no edit changes it.
    const { adaptation, ...review } = opened;
    const page = new ReviewPage(root, capture, me, project ?? null, withTempIds(review), adaptation, signal?.signals ?? [], frames);
    return () => page.dispose();
  } catch (err) {
    frames.abort.abort();
    // A refusal (e.g. a capture not assigned to an annotator who may not pick it) says so
    // and points to the caller's queue instead of a generic error page.
    if (err instanceof ApiError && err.status === 403) {
      clear(root, h("div", { class: "loading-page", "data-testid": "review-refused" }, h("h1", {}, capture.name), h("p", { class: "error-text" }, err.message), h("a", { href: "/queue/" }, "← My queue")));
      return () => {};
    }
    throw err;
  }
}

function renderNotReady(root: HTMLElement, capture: Capture): () => void {
  const text =
    capture.status === "failed"
      ? `This capture could not be read: ${capture.error ?? "no reason was recorded"}`
      : `This capture is ${capture.status}; the page reloads when it is ready.`;
  clear(root, h("div", { class: "loading-page" }, h("h1", {}, capture.name), h("p", { class: capture.status === "failed" ? "error-text" : "" }, text), h("a", { href: "/" }, "← Captures")));
  if (capture.status === "failed") return () => {};
  const timer = setInterval(async () => {
    const now = await get<Capture>(`/api/captures/${capture.id}/`).catch(() => null);
    if (now && now.status !== capture.status) location.reload();
  }, 2000);
  return () => clearInterval(timer);
}

class ReviewPage {
  private readonly session: ReviewSession;
  private readonly playback: PlaybackController;
  private readonly stage: Stage;
  private readonly timeline: Timeline;
  private readonly sidebar: Sidebar;
  private readonly commands: Commands;
  private readonly suggestions: Suggestions;
  private readonly notes: Notes;
  private readonly videos: VideoDock;
  private readonly labels: Label[];
  private readonly el: Elements;
  private readonly onKey = (e: KeyboardEvent) => {
    const command = pageCommand(e, undefined, this.notes?.hotkeys() ?? "");
    if (command) this.command(command);
  };

  constructor(
    root: HTMLElement,
    private readonly capture: ReadyCapture,
    me: Me,
    private readonly project: Project | null,
    review: Review,
    adaptation: Adaptation,
    private signals: Signal[],
    private readonly frames: FrameFeed,
  ) {
    // Labels that may be applied: the taxonomy without its retired labels, in order.
    this.labels = (project?.labels ?? []).filter((l) => !l.retired);
    this.session = new ReviewSession(capture.id, capture.n_frames, review, {
      changed: () => this.refresh(),
      notice: (text, error) => toast(text, error ? "error" : "info"),
      saving: (n) => this.showSaveState(n),
      settled: (r) => {
        void this.loadEvents();
        // An edit makes new segments; their suggestions are asked for once the edits settle.
        this.suggestions.askForNew(r.segments);
      },
      conflict: (changes, unsaved) => void showConflict(changes, unsaved).then(() => this.loadEvents()),
    });
    this.playback = new PlaybackController(capture.fps, capture.n_frames, frameFromUrl(capture.n_frames), (frame, playing) => this.onPlayFrame(frame, playing));
    const layout = buildLayout(capture, me, {
      command: (c) => this.command(c),
      submit: () => void this.submit(false),
      submitNext: () => void this.submit(true),
      help: () => this.commands.toggleHelp(),
      follow: () => this.el.follow.classList.toggle("active", this.stage.toggleFollow()),
      speed: (v) => this.setSpeed(v),
      zoom: (factor) => this.timeline.zoom(factor, this.playback.frame),
      importAnnotations: () => void this.importAnnotations(),
    });
    this.el = layout.el;
    clear(root, layout.root);
    this.stage = new Stage(this.el, capture, me, frames);
    // Reference videos float over the stage and follow the playback clock.
    this.videos = new VideoDock(this.el.viewport.parentElement!, { captureId: capture.id, fps: capture.fps, nFrames: capture.n_frames, playback: this.playback, floating: true });
    this.timeline = this.makeTimeline();
    this.sidebar = new Sidebar(this.el, capture, this.labels, adaptation, {
      label: (name) => this.session.labelAt(this.playback.frame, name),
      show: (other) => {
        this.session.show(other);
        if (!other) void this.loadEvents();
      },
    });
    this.commands = new Commands({
      session: this.session, playback: this.playback, labels: this.labels,
      segmentHere: () => this.segmentHere(),
      reveal: (f) => this.timeline.reveal(f),
      zoom: (factor, f) => this.timeline.zoom(factor, f),
      setSpeed: (v) => this.setSpeed(v),
      notice: (text, error) => toast(text, error ? "error" : "info"),
      refresh: () => this.refresh(),
    });
    // Arrived suggestions show in the side panel and in the timeline's segments.
    this.suggestions = new Suggestions(capture.id, () => this.refresh());
    this.notes = new Notes({
      session: this.session, captureId: capture.id, frame: () => this.playback.frame,
      goTo: (f) => {
        this.playback.seekAndPause(f);
        this.timeline.reveal(this.playback.frame);
        this.refresh();
      },
      refresh: () => this.refresh(),
    });
    frames.onChunk = () => this.stage.loaded(this.playback.frame);
    if (frames.store.loadedFrames) this.stage.loaded(this.playback.frame);
    void signalsWait(frames).then(() => this.loadFullSignals()).finally(frames.resume);
    document.addEventListener("keydown", this.onKey);
    this.refresh();
    void this.loadEvents();
    void this.sidebar.loadOtherReviews(project, me);
    void this.suggestions.load();
    void this.notes.load(project?.id ?? null);
  }

  dispose(): void {
    this.suggestions.dispose();
    this.videos.dispose();
    this.playback.dispose();
    this.commands.dispose();
    document.removeEventListener("keydown", this.onKey);
    this.stage.dispose();
  }

  private makeTimeline(): Timeline {
    const s = this.session;
    return new Timeline(this.el.timeline, {
      seek: (f) => {
        this.playback.seek(f);
        this.refresh();
      },
      selectCut: (id) => s.select(id),
      moveCut: (id, frame) => s.perform({ kind: "move", cutId: id, frame }),
      insertAt: (frame) => s.insertAt(frame),
      restoreCut: (id) => s.perform({ kind: "fate", cutId: id, fate: "pending" }),
      setLoop: (range) => {
        this.playback.setLoop(range);
        this.refresh();
      },
    });
  }

  // ---- state → screen ------------------------------------------------------------------

  private command(c: Command): void {
    if (c.kind === "comment") void this.notes.add(c.on === "segment" ? this.segmentHere() : undefined);
    else if (c.kind === "commentJump") this.notes.jump(c.direction);
    else if (c.kind === "attribute") void this.notes.attributeKey(c.hotkey, c.back, this.segmentHere());
    else this.commands.run(c);
    this.refresh();
  }

  private refresh(): void {
    const frame = this.playback.frame;
    this.timeline.update(this.timelineModel(frame));
    this.stage.show(frame);
    this.renderSide();
    showControls(this.el, this.session, this.playback);
  }

  /** The cheap part of refresh(), run on every animation frame while playing. */
  private onPlayFrame(frame: number, playing: boolean): void {
    this.timeline.reveal(frame);
    this.stage.show(frame);
    this.timeline.update(this.timelineModel(frame));
    // The side panels describe the segment under the playhead: redraw when it changes.
    if (segmentAt(this.session.review.segments, frame) !== this.sidebar.shownSegment) this.renderSide();
    if (!playing) this.refresh();
  }

  private timelineModel(playhead: number): TimelineModel {
    const s = this.session;
    return {
      nFrames: this.capture.n_frames, fps: this.capture.fps, signals: this.signals, cuts: s.review.cuts,
      segments: s.readOnly ? s.review.segments : this.suggestions.all(s.review.segments),
      labels: this.project?.labels ?? [], playhead,
      selectedCutId: s.selectedCutId, loop: this.playback.loop, readOnly: s.locked() !== null,
    };
  }

  /** The segment under the playhead, with the suggested label of the own review's segment. */
  private segmentHere() {
    const segment = segmentAt(this.session.review.segments, this.playback.frame);
    return this.session.readOnly ? segment : this.suggestions.on(segment);
  }

  private renderSide(): void {
    const segment = this.segmentHere();
    this.sidebar.render(this.session, segment);
    this.notes?.render(this.el.comments, this.el.attributes, this.el.attributesSection, segment);
  }

  private setSpeed(speed: number): void {
    this.playback.setSpeed(speed);
    (this.el.speed as HTMLSelectElement).value = String(speed);
  }

  private showSaveState(pending: number): void {
    this.el.saveState.textContent = pending ? `Saving ${pending}…` : "Saved";
    this.el.saveState.classList.toggle("busy", pending > 0);
  }

  /** The own review's activity log; the undo history is read from it (it survives a reload). */
  private async loadEvents(): Promise<void> {
    if (this.session.readOnly) return;
    const asOf = this.session.sent;
    const events = await this.sidebar.loadEvents(this.session.locked() ? undefined : (e) => void this.askRestore(e));
    if (events) this.session.readHistory(events, asOf);
  }

  private async askRestore(e: ReviewEvent): Promise<void> {
    if (await confirmRestore(e)) this.session.restore(e.id, `${e.action} ${eventDetail(e)}`.trim());
  }

  /** Once the first pose is on screen, the lanes at every frame's value (stage.ts). */
  private async loadFullSignals(): Promise<void> {
    const full = await fullSignals(this.capture, this.signals, this.frames.abort.signal);
    if (!full) return;
    this.signals = full;
    this.el.timeline.dataset.signalStep = String(Math.max(1, ...full.map((sig) => sig.step)));
    this.refresh();
    // The timeline draws on the next animation frame, before this callback (queued after
    // its own): milliseconds from navigation to every lane drawn at full resolution.
    requestAnimationFrame(() => (this.el.timeline.dataset.lanesMs = String(Math.round(performance.now()))));
  }

  /** Import a file's segments into the own review (annotationsDialog.ts); the review the
   * server answers with replaces the one shown, and the history is read from its log. */
  private async importAnnotations(): Promise<void> {
    const s = this.session;
    const locked = s.locked();
    if (locked) return toast(locked, "error");
    if (s.saver.pending) return toast("Wait until your edits are saved, then import.", "error");
    await openImportDialog({
      captureId: this.capture.id,
      into: "review",
      version: () => s.saver.server.version,
      imported: (answer, summary) => {
        if (answer.review) s.replaced(withTempIds(answer.review));
        toast(summary);
      },
    });
  }

  private async submit(next: boolean): Promise<void> {
    const s = this.session;
    // Proposals the annotator did not accept: unlabelled segments that show a suggested label.
    const proposed = s.review.segments.filter((seg) => !seg.label && this.suggestions.on(seg)?.suggested_label).length;
    if (s.locked() || s.saver.pending || !(await confirmSubmit(s.review, next, proposed))) return;
    try {
      await s.submit();
      toast("Review submitted.");
      void this.loadEvents();
    } catch (err) {
      toast(`Not submitted: ${err instanceof Error ? err.message : String(err)}`, "error");
      next = false;
    }
    this.refresh();
    if (next) await openNext(this.capture);
  }
}

/** The transport and top bar as the session and playback stand: buttons, banner, read-outs. */
function showControls(el: Elements, session: ReviewSession, playback: PlaybackController): void {
  const review = session.review;
  el.play.replaceChildren(icon(playback.playing ? "pause" : "play"));
  const loop = playback.loop;
  el.hudState.textContent = [playback.playing ? "playing" : "paused", `${playback.state.speed}×`, loop ? `loop ${loop.start}–${loop.stop - 1}` : null].filter(Boolean).join(" · ");
  el.loop.classList.toggle("active", loop !== null);
  const locked = session.locked() !== null;
  el.undo.toggleAttribute("disabled", locked || session.history.past.length === 0);
  el.redo.toggleAttribute("disabled", locked || session.history.future.length === 0);
  for (const id of ["accept", "delete", "insert", "submit", "submit-next", "import-annotations"]) el[id].toggleAttribute("disabled", locked);
  el.submit.textContent = review.status === "submitted" ? "Submitted" : review.status === "returned" ? "Resubmit" : "Submit review";
  const returned = review.status === "returned" ? `Returned by a reviewer: “${review.return_comment ?? ""}” — edit and resubmit.` : "";
  const banner = session.readOnly ? `Viewing ${review.annotator.username}'s review — read-only.` : locked ? "You submitted this review — read-only." : returned;
  el.banner.textContent = banner;
  el.banner.toggleAttribute("hidden", !banner);
}
