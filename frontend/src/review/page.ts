// The review page: skeleton player on top, timeline lanes under it, labels and the
// activity log at the side. Every edit is applied on screen at once and saved through
// the API straight away (saver.ts); undo/redo are edits too, so the audit log is complete.

import { ApiError, get, post } from "../api/client";
import { isReady } from "../api/types";
import type { Adaptation, Capture, Cut, ReadyCapture, Label, Me, OpenedReview, Project, Review, ReviewEvent, Segment, Signal, SignalResponse, Suggestions } from "../api/types";
import { advance, frameOf, nextSpeed, seek, togglePlay, type Playback } from "../player/clock";
import { MAX_JOINTS, SkeletonView, TooManyJoints } from "../player/skeletonView";
import { clear, confirmDialog, dialog, h, toast } from "../ui/dom";
import { icon } from "../ui/icons";
import { nextInQueue, returnReview } from "../queue/api";
import { navigate } from "../router";
import { promptDialog } from "../ui/prompt";
import { FrameStore, decodeFloat32, loadFrames } from "./frames";
import { changeFor, emptyHistory, record, redo, undo, type Change, type History } from "./history";
import { labelForHotkey, pageCommand } from "./keys";
import { HELP, type Command } from "./keymap";
import { openPalette } from "./palette";
import { Saver } from "./saver";
import { applyEdit, clampFrame, describeDifferences, EditError, neighbourCut, segmentAt, withTempIds, type Edit } from "./state";
import { buildLayout, type Elements } from "./layout";
import { renderAdaptation, renderEvents, renderLabels, renderSelection, renderStats } from "./panels";
import { Timeline } from "./timeline";
import { formatTime } from "./timescale";

/** `/signal/?encoding=float32`: each signal's values as base64 little-endian float32. */
type PackedSignalResponse = Omit<SignalResponse, "signals"> & { signals: (Omit<Signal, "values"> & { data: string })[] };

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

/** A capture's poses loading in the background, with a hook for each chunk that lands. */
class FrameFeed {
  readonly store: FrameStore;
  readonly abort = new AbortController();
  readonly started = performance.now();
  readonly done: Promise<void>;
  /** Settles when the first chunk has landed (the first pose can be drawn), or loading ended. */
  readonly first: Promise<void>;
  /** Lets the poses after the first chunk load (see signalsWait); aborting does too. */
  resume: () => void = () => {};
  onChunk: () => void = () => {};

  constructor(capture: ReadyCapture, maxJoints: number, holdAfterFirst: boolean) {
    // Poses the player will not draw are not fetched (nor memory set aside for them).
    const drawable = jointCount(capture) <= maxJoints;
    this.store = new FrameStore(capture.n_frames, drawable ? jointCount(capture) : 0);
    let landed = () => {};
    this.first = new Promise<void>((resolve) => (landed = resolve));
    const onChunk = () => {
      landed();
      this.onChunk();
    };
    const gate = new Promise<void>((resolve) => (this.resume = resolve));
    if (!holdAfterFirst) this.resume();
    this.abort.signal.addEventListener("abort", () => this.resume());
    this.done = drawable ? loadFrames(capture.id, this.store, frameFromUrl(capture.n_frames), onChunk, this.abort.signal, gate) : Promise.resolve();
    void this.done.finally(landed);
  }
}

/**
 * The previous request order, `?signals=after-poses`: the full-resolution signals asked for
 * once every pose has loaded. Kept so benchmarks/review_long_take.py can time both orders
 * in the same run.
 */
function signalsAfterPoses(search = location.search): boolean {
  return new URLSearchParams(search).get("signals") === "after-poses";
}

/**
 * When the full-resolution signals are asked for: once the first pose is on screen. The
 * other poses wait until the lanes are drawn (FrameFeed.resume): an hour-long take's poses
 * take seconds to load, its signals a fraction of one, and on a small server the signals'
 * request would otherwise queue behind pose chunks.
 */
function signalsWait(frames: FrameFeed): Promise<void> {
  return signalsAfterPoses() ? frames.done : frames.first;
}

function jointCount(capture: ReadyCapture): number {
  return Math.max(capture.n_joints ?? 0, capture.skeleton?.joints.length ?? 0);
}

function maxJoints(me: Me): number {
  return me.limits?.max_joints ?? MAX_JOINTS;
}

/** The frame asked for by `?frame=N` (the library links a segment's start this way), else 0. */
export function frameFromUrl(nFrames: number, search = location.search): number {
  const frame = Number(new URLSearchParams(search).get("frame"));
  return Number.isInteger(frame) && frame > 0 ? Math.min(frame, Math.max(nFrames - 1, 0)) : 0;
}

function listOf<T>(value: T[] | { results: T[] }): T[] {
  return Array.isArray(value) ? value : value.results;
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
  private review: Review;
  private readonly own: Review;
  private history: History = emptyHistory();
  private playback: Playback;
  private selectedCutId: number | null = null;
  private readOnly = false;
  private helpOpen: HTMLElement | null = null;
  private nextTempId = -1;
  private lastTick = 0;
  private raf = 0;
  private shownFrame = -1;
  private floorSet = false;
  private panelSegment: Segment | undefined;
  /** Suggested labels of the own review's unlabelled segments by "start-stop" (a worker computes them). */
  private readonly suggested = new Map<string, string | null>();
  private suggestionTimer = 0;
  private suggestionDelay = 2000;
  private readonly saver: Saver;
  private readonly store: FrameStore;
  private readonly player: SkeletonView | null;
  private readonly timeline: Timeline;
  private readonly abort: AbortController;
  private readonly labels: Label[];
  private readonly el: Elements;
  private readonly onKey = (e: KeyboardEvent) => {
    const command = pageCommand(e);
    if (command) this.command(command);
  };

  constructor(
    root: HTMLElement,
    private readonly capture: ReadyCapture,
    private readonly me: Me,
    private readonly project: Project | null,
    review: Review,
    private readonly adaptation: Adaptation,
    private signals: Signal[],
    frames: FrameFeed,
  ) {
    this.review = review;
    this.own = review;
    // Below the temporary ids an unstarted review's candidates carry.
    this.nextTempId = Math.min(0, ...review.cuts.map((c) => c.id)) - 1;
    this.labels = project?.labels ?? [];
    this.playback = { position: frameFromUrl(capture.n_frames), playing: false, speed: 1, fps: capture.fps, nFrames: capture.n_frames, loop: null };
    this.saver = new Saver(capture.id, review, {
      saved: (r, idle, renamed) => this.onSaved(r, idle, renamed),
      conflict: (r, unsaved, message) => void this.onConflict(r, unsaved, message),
      failed: (r, unsaved, message) => this.onFailed(r, unsaved, message),
      busy: (n) => this.showSaveState(n),
    });
    const layout = buildLayout(capture, me, {
      command: (c) => this.command(c),
      submit: () => void this.submit(false),
      submitNext: () => void this.submit(true),
      help: () => this.toggleHelp(),
      follow: () => this.toggleFollow(),
      speed: (v) => this.setSpeed(v),
      zoom: (factor) => this.timeline.zoom(factor, this.frame()),
    });
    this.el = layout.el;
    clear(root, layout.root);
    this.player = this.makePlayer();
    this.timeline = new Timeline(this.el.timeline, {
      seek: (f) => this.seekTo(f),
      selectCut: (id) => this.select(id),
      acceptCut: (id) => this.perform({ kind: "fate", cutId: id, fate: "accepted" }),
      moveCut: (id, frame) => this.perform({ kind: "move", cutId: id, frame }),
      insertAt: (frame) => this.perform({ kind: "insert", frame, tempId: this.nextTempId-- }),
      restoreCut: (id) => this.perform({ kind: "fate", cutId: id, fate: "pending" }),
      setLoop: (range) => {
        this.playback = range ? seek({ ...this.playback, loop: range }, range.start) : { ...this.playback, loop: null };
        this.refresh();
      },
    });
    this.store = frames.store;
    this.abort = frames.abort;
    frames.onChunk = () => this.onFramesLoaded(frames.started);
    if (this.store.loadedFrames) this.onFramesLoaded(frames.started);
    void signalsWait(frames).then(() => this.loadFullSignals()).finally(frames.resume);
    document.addEventListener("keydown", this.onKey);
    this.refresh();
    void this.loadEvents();
    void this.loadOtherReviews();
    void this.loadSuggestions();
  }

  dispose(): void {
    this.abort.abort();
    clearTimeout(this.suggestionTimer);
    cancelAnimationFrame(this.raf);
    document.removeEventListener("keydown", this.onKey);
    this.player?.dispose();
  }

  // ---- layout --------------------------------------------------------------------------

  private makePlayer(): SkeletonView | null {
    const joints = jointCount(this.capture);
    const limit = maxJoints(this.me);
    if (joints > limit) {
      const text = `No 3D view: this capture has ${new TooManyJoints(joints, limit).message}. The timeline still works.`;
      this.el.viewport.append(h("div", { class: "no-webgl", "data-testid": "too-many-joints" }, text));
      this.el.loading.hidden = true;
      return null;
    }
    try {
      return new SkeletonView(this.el.viewport, this.capture.skeleton!, limit);
    } catch (err) {
      this.el.viewport.append(h("div", { class: "no-webgl" }, `3D view unavailable (${err instanceof Error ? err.message : "no WebGL"}); the timeline still works.`));
      return null;
    }
  }

  // ---- state → screen ------------------------------------------------------------------

  private frame(): number {
    return frameOf(this.playback);
  }

  private refresh(): void {
    const frame = this.frame();
    this.timeline.update({
      nFrames: this.capture.n_frames,
      fps: this.capture.fps,
      signals: this.signals,
      cuts: this.review.cuts,
      segments: this.review.segments,
      labels: this.labels,
      playhead: frame,
      selectedCutId: this.selectedCutId,
      loop: this.playback.loop,
      readOnly: this.locked() !== null,
    });
    this.showFrame(frame);
    this.renderSide();
    this.el.play.replaceChildren(icon(this.playback.playing ? "pause" : "play"));
    const loop = this.playback.loop;
    this.el.hudState.textContent = [
      this.playback.playing ? "playing" : "paused",
      `${this.playback.speed}×`,
      loop ? `loop ${loop.start}–${loop.stop - 1}` : null,
    ].filter(Boolean).join(" · ");
    this.el.loop.classList.toggle("active", this.playback.loop !== null);
    const locked = this.locked() !== null;
    this.el.undo.toggleAttribute("disabled", locked || this.history.past.length === 0);
    this.el.redo.toggleAttribute("disabled", locked || this.history.future.length === 0);
    for (const id of ["accept", "delete", "insert", "submit", "submit-next"]) this.el[id].toggleAttribute("disabled", locked);
    this.el.submit.textContent = this.review.status === "submitted" ? "Submitted" : this.review.status === "returned" ? "Resubmit" : "Submit review";
    const returned = this.review.status === "returned" ? `Returned by a reviewer: “${this.review.return_comment ?? ""}” — edit and resubmit.` : "";
    const banner = this.readOnly ? `Viewing ${this.review.annotator.username}'s review — read-only.` : locked ? "You submitted this review — read-only." : returned;
    this.el.banner.textContent = banner;
    this.el.banner.toggleAttribute("hidden", !banner);
  }

  private showFrame(frame: number): void {
    const c = this.capture;
    this.el.hudFrame.textContent = `Frame ${frame} / ${c.n_frames - 1}`;
    this.el.hudTime.textContent = `${formatTime(frame, c.fps)} / ${formatTime(c.n_frames - 1, c.fps)} · ${c.fps} fps`;
    if (frame === this.shownFrame || !this.player) return;
    const shown = this.store.has(frame) ? frame : this.store.nearestLoaded(frame);
    if (shown === null) return;
    this.player.setPose(this.store.pose(shown));
    this.shownFrame = shown === frame ? frame : -1;
    // Milliseconds from navigation to the first pose on screen: the "opens in" figure.
    this.el.viewport.dataset.firstPoseMs ??= String(Math.round(performance.now()));
  }

  private renderSide(): void {
    const segment = this.withSuggestion(segmentAt(this.review.segments, this.frame()));
    this.panelSegment = segment;
    renderLabels(this.el.labels, this.activeLabels(), segment?.label ?? null, this.locked() !== null, (name) => this.labelCurrent(name));
    renderSelection(this.el.selection, this.selectedCut(), segment, this.capture.fps);
    renderStats(this.el.stats, this.review);
    renderAdaptation(this.el.adaptation, this.adaptation);
  }

  private selectedCut(): Cut | undefined {
    return this.review.cuts.find((c) => c.id === this.selectedCutId && c.fate !== "deleted");
  }

  private showSaveState(pending: number): void {
    this.el.saveState.textContent = pending ? `Saving ${pending}…` : "Saved";
    this.el.saveState.classList.toggle("busy", pending > 0);
  }

  private onFramesLoaded(started: number): void {
    const s = this.store;
    const share = s.loadedFrames / s.nFrames;
    this.el.loadingBar.style.width = `${(share * 100).toFixed(1)}%`;
    this.el.loading.toggleAttribute("hidden", share >= 1 && !s.error);
    if (s.error) this.el.loading.replaceChildren(h("span", { class: "error-text" }, `Could not load frames: ${s.error}`));
    if (share >= 1) this.el.loading.dataset.done = `${Math.round(performance.now() - started)}`;
    const floor = s.floorLevel();
    if (floor !== null && !this.floorSet) {
      this.player?.setFloor(floor);
      this.floorSet = true;
    }
    this.shownFrame = -1;
    this.showFrame(this.frame());
  }

  /**
   * The first paint uses signals decimated to a few thousand points; once the first pose
   * is on screen (signalsWait), fetch them at full frame resolution so zooming in shows
   * every frame.
   */
  private async loadFullSignals(): Promise<void> {
    if (this.abort.signal.aborted || !this.signals.some((sig) => sig.step > 1)) return;
    // Every frame's value as base64 float32: 5.3 bytes a value instead of ~9 of JSON, and no numbers to parse.
    const full = await get<PackedSignalResponse>(`/api/captures/${this.capture.id}/signal/?max_points=${this.capture.n_frames}&encoding=float32`).catch(() => null);
    if (!full || this.abort.signal.aborted) return;
    this.signals = full.signals.map(({ data, ...sig }) => ({ ...sig, values: Array.from(decodeFloat32(data)) }));
    this.el.timeline.dataset.signalStep = String(Math.max(1, ...this.signals.map((sig) => sig.step)));
    this.refresh();
    // The timeline draws on the next animation frame, before this callback (queued after
    // its own): milliseconds from navigation to every lane drawn at full resolution.
    requestAnimationFrame(() => (this.el.timeline.dataset.lanesMs = String(Math.round(performance.now()))));
  }

  // ---- editing -------------------------------------------------------------------------

  /** Why this review cannot be edited now, or null if it can. */
  private locked(): string | null {
    if (this.readOnly) return `You are viewing ${this.review.annotator.username}'s review, read-only.`;
    if (this.review.status === "submitted") return "This review was submitted; it is read-only now.";
    return null;
  }

  private perform(edit: Edit): void {
    const locked = this.locked();
    if (locked) {
      toast(locked, "error");
      return;
    }
    try {
      const change = changeFor(this.review, edit);
      this.review = applyEdit(this.review, edit, this.capture.n_frames);
      this.history = record(this.history, change);
      if (edit.kind === "insert") this.selectedCutId = edit.tempId;
      this.saver.push([edit], change.title);
    } catch (err) {
      if (!(err instanceof EditError)) throw err;
      toast(err.message, "error");
    }
    this.refresh();
  }

  private replay(step: { history: History; edits: Edit[]; change: Change } | null, verb: string): void {
    if (!step) {
      toast(`Nothing to ${verb}.`);
      return;
    }
    try {
      let next = this.review;
      for (const edit of step.edits) next = applyEdit(next, edit, this.capture.n_frames);
      this.review = next;
      this.history = step.history;
      if (step.edits.length) this.saver.push(step.edits, `${verb} ${step.change.title}`);
      toast(`${verb[0].toUpperCase()}${verb.slice(1)}: ${step.change.title}`);
    } catch (err) {
      toast(err instanceof Error ? err.message : String(err), "error");
    }
    this.refresh();
  }

  private async submit(next: boolean): Promise<void> {
    if (this.locked() || this.saver.pending) return;
    const pending = this.review.cuts.filter((c) => c.fate === "pending").length;
    const unlabelled = this.review.segments.filter((s) => !s.label).length;
    // Submitting keeps every cut not deleted, pending candidates included: say so, with the count.
    const candidates = `${pending} pending candidate${pending === 1 ? "" : "s"}`;
    const ok = await confirmDialog(next ? "Submit and open the next capture?" : "Submit this review?", [
      h("p", {}, "A submitted review counts towards agreement and the library, and can no longer be edited."),
      pending
        ? h("p", { "data-testid": "submit-pending" }, h("strong", {}, `${candidates} will be kept as cuts.`), ` Accept or delete ${pending === 1 ? "it" : "them"} first to decide each one.`)
        : null,
      unlabelled ? h("p", { class: "muted", "data-testid": "submit-unlabelled" }, `${unlabelled} unlabelled segment${unlabelled === 1 ? "" : "s"} will be left out of the library.`) : null,
    ], pending ? `Submit, keeping ${pending}` : "Submit");
    if (!ok) return;
    try {
      this.review = await post<Review>(`/api/captures/${this.capture.id}/review/submit/`, { version: this.saver.server.version });
      this.saver.server = this.review;
      this.history = emptyHistory();
      toast("Review submitted.");
      void this.loadEvents();
    } catch (err) {
      toast(`Not submitted: ${err instanceof Error ? err.message : String(err)}`, "error");
      next = false;
    }
    this.refresh();
    if (next) await this.openNext();
  }

  /** The oldest open capture of the caller's queue in this project, or the queue itself. */
  private async openNext(): Promise<void> {
    const item = await nextInQueue(this.capture.project, this.capture.id).catch(() => null);
    if (item) navigate(`/captures/${item.capture.id}/`);
    else {
      toast("Your queue has nothing else open.");
      navigate(`/queue/?project=${this.capture.project}`);
    }
  }

  /** Labels that may be applied: the taxonomy without its retired labels, in order. */
  private activeLabels(): Label[] {
    return this.labels.filter((l) => !l.retired);
  }

  private labelCurrent(label: string | null): void {
    const segment = segmentAt(this.review.segments, this.frame());
    if (!segment) return;
    this.perform({ kind: "label", start: segment.start, stop: segment.stop, label });
  }

  private onSaved(review: Review, idle: boolean, renamed: Map<number, number>): void {
    if (renamed.size) {
      this.review = { ...this.review, cuts: this.review.cuts.map((c) => ({ ...c, id: renamed.get(c.id) ?? c.id })) };
      if (this.selectedCutId !== null) this.selectedCutId = renamed.get(this.selectedCutId) ?? this.selectedCutId;
    }
    if (idle) {
      this.review = review;
      this.refresh();
      void this.loadEvents();
      // An edit makes new segments; their suggestions are asked for once the edits settle.
      if (review.segments.some((s) => !s.label && !this.suggested.has(`${s.start}-${s.stop}`))) this.askSuggestions(800);
    }
  }

  private async onConflict(current: Review, unsaved: string[], message: string): Promise<void> {
    const changes = describeDifferences(this.review, current);
    this.review = current;
    this.history = emptyHistory();
    this.refresh();
    // The server's text is for API clients (it names the review and says to reload); the
    // page has already loaded the current version, so it says that instead.
    void message;
    await dialog("This review changed elsewhere", [
      h("p", { "data-testid": "conflict-text" }, "Your review was saved from another tab or window first. This page shows that version now."),
      h("p", {}, "What changed:"),
      h("ul", { "data-testid": "conflict-changes" }, ...(changes.length ? changes : ["(nothing visible)"]).map((line) => h("li", {}, line))),
      unsaved.length ? h("p", {}, "Not saved — redo these if you still want them:") : null,
      unsaved.length ? h("ul", { "data-testid": "conflict-unsaved" }, ...unsaved.map((t) => h("li", {}, t))) : null,
    ]);
    void this.loadEvents();
  }

  private onFailed(current: Review | null, unsaved: string[], message: string): void {
    if (current) {
      this.review = current;
      this.history = emptyHistory();
    }
    toast(`Not saved (${unsaved.join(", ")}): ${message}`, "error");
    this.refresh();
  }

  // ---- playback ------------------------------------------------------------------------

  private seekTo(frame: number): void {
    this.playback = seek(this.playback, frame);
    this.refresh();
  }

  private setSpeed(speed: number): void {
    this.playback = { ...this.playback, speed };
    (this.el.speed as HTMLSelectElement).value = String(speed);
  }

  private toggleFollow(): void {
    if (!this.player) return;
    this.player.follow = !this.player.follow;
    this.el.follow.classList.toggle("active", this.player.follow);
  }

  private tick = (now: number): void => {
    const dt = (now - this.lastTick) / 1000;
    this.lastTick = now;
    this.playback = advance(this.playback, dt);
    const frame = this.frame();
    this.timeline.reveal(frame);
    this.refreshPlayhead(frame);
    if (this.playback.playing) this.raf = requestAnimationFrame(this.tick);
    else this.refresh();
  };

  /** The cheap part of refresh(), run on every animation frame while playing. */
  private refreshPlayhead(frame: number): void {
    this.showFrame(frame);
    this.timeline.update({ ...this.timelineModel(), playhead: frame });
    // The side panels describe the segment under the playhead: redraw when it changes.
    const segment = segmentAt(this.review.segments, frame);
    if (segment !== this.panelSegment) this.renderSide();
  }

  private timelineModel() {
    return {
      nFrames: this.capture.n_frames, fps: this.capture.fps, signals: this.signals, cuts: this.review.cuts,
      segments: this.review.segments, labels: this.labels, playhead: this.frame(),
      selectedCutId: this.selectedCutId, loop: this.playback.loop, readOnly: this.locked() !== null,
    };
  }

  // ---- commands ------------------------------------------------------------------------

  private command(c: Command): void {
    if (!this.editCommand(c)) this.viewCommand(c);
    this.refresh();
  }

  /** Playback, navigation and view commands. */
  private viewCommand(c: Command): void {
    const frame = this.frame();
    switch (c.kind) {
      case "play":
        this.playback = togglePlay(this.playback);
        this.lastTick = performance.now();
        if (this.playback.playing) this.raf = requestAnimationFrame(this.tick);
        break;
      case "step":
      case "home":
      case "end": {
        const target = c.kind === "step" ? frame + c.frames : c.kind === "home" ? 0 : this.capture.n_frames - 1;
        this.playback = { ...seek(this.playback, clampFrame(target, this.capture.n_frames)), playing: false };
        this.timeline.reveal(this.frame());
        break;
      }
      case "jump": {
        const cut = neighbourCut(this.review.cuts, frame, c.direction);
        if (!cut) break;
        this.playback = { ...seek(this.playback, cut.frame), playing: false };
        this.selectedCutId = cut.id;
        this.timeline.reveal(cut.frame);
        break;
      }
      case "loop": {
        const segment = segmentAt(this.review.segments, frame);
        this.playback = { ...this.playback, loop: this.playback.loop || !segment ? null : { start: segment.start, stop: segment.stop } };
        break;
      }
      case "speed":
        this.setSpeed(nextSpeed(this.playback.speed, c.direction));
        break;
      case "zoom":
        this.timeline.zoom(c.factor, frame);
        break;
      case "help":
        this.toggleHelp();
        break;
      case "escape":
        if (this.helpOpen) this.toggleHelp();
        else this.selectedCutId = null;
        break;
    }
  }

  /** Commands that change the review; false if `c` is not one of them. */
  private editCommand(c: Command): boolean {
    const segment = this.withSuggestion(segmentAt(this.review.segments, this.frame()));
    switch (c.kind) {
      case "accept":
      case "delete":
        this.changeSelectedCut(c.kind);
        return true;
      case "insert":
        this.perform({ kind: "insert", frame: this.frame(), tempId: this.nextTempId-- });
        return true;
      case "label": {
        // Labels without hotkeys answer to their position in the taxonomy instead.
        const label = labelForHotkey(this.activeLabels(), c.hotkey);
        if (label) this.labelCurrent(label.name);
        else toast(`No label has hotkey ${c.hotkey}.`);
        return true;
      }
      case "clearLabel":
        this.labelCurrent(null);
        return true;
      case "palette":
        if (!this.locked()) openPalette(this.activeLabels(), (name) => this.labelCurrent(name));
        return true;
      case "acceptSuggestion":
        if (segment?.suggested_label) this.labelCurrent(segment.suggested_label);
        else toast("No suggested label for the segment under the playhead.");
        return true;
      case "undo":
      case "redo":
        if (!this.locked()) this.replay((c.kind === "undo" ? undo : redo)(this.history, this.review, this.saver.resolve), c.kind);
        return true;
      default:
        return false;
    }
  }

  private changeSelectedCut(action: "accept" | "delete"): void {
    const cut = this.selectedCut();
    if (!cut) toast("Select a cut first: click it, or jump to it with Shift+←/→.");
    // Accepting a kept cut would only rewrite its fate (and lose "moved"): say so instead.
    else if (action === "accept" && cut.fate !== "pending") toast(`The cut at ${cut.frame} is already kept (${cut.origin === "inserted" ? "inserted" : cut.fate}).`);
    else this.perform({ kind: "fate", cutId: cut.id, fate: action === "accept" ? "accepted" : "deleted" });
    if (cut && action === "delete") this.selectedCutId = null;
  }

  private select(id: number | null): void {
    this.selectedCutId = id;
    this.refresh();
  }

  private toggleHelp(): void {
    if (this.helpOpen) {
      this.helpOpen.remove();
      this.helpOpen = null;
      return;
    }
    this.helpOpen = h(
      "div",
      { class: "modal-backdrop help", "data-testid": "help", onclick: () => this.toggleHelp() },
      h(
        "div",
        { class: "modal" },
        h("h2", {}, "Keyboard"),
        h("table", { class: "keys" }, ...HELP.map(([keys, what]) => h("tr", {}, h("th", {}, h("kbd", {}, keys)), h("td", {}, what)))),
      ),
    );
    document.body.append(this.helpOpen);
  }

  // ---- label suggestions ---------------------------------------------------------------

  /** `segment` with the suggested label of the own review's segment of the same span. */
  private withSuggestion(segment: Segment | undefined): Segment | undefined {
    if (!segment || this.readOnly || segment.label) return segment;
    return { ...segment, suggested_label: this.suggested.get(`${segment.start}-${segment.stop}`) ?? null };
  }

  private askSuggestions(delayMs: number): void {
    clearTimeout(this.suggestionTimer);
    this.suggestionTimer = window.setTimeout(() => void this.loadSuggestions(), delayMs);
  }

  /** Suggestions are computed by a worker after the page opens; ask until none is pending. */
  private async loadSuggestions(): Promise<void> {
    const body = await get<Suggestions>(`/api/captures/${this.capture.id}/review/suggestions/`).catch(() => null);
    if (!body || this.abort.signal.aborted) return;
    for (const s of body.suggestions) this.suggested.set(`${s.start}-${s.stop}`, s.label);
    this.renderSide();
    // Poll while the worker computes; less often the longer it takes (a busy or stopped worker).
    if (!body.pending) {
      this.suggestionDelay = 2000;
      return;
    }
    this.askSuggestions(this.suggestionDelay);
    this.suggestionDelay = Math.min(this.suggestionDelay * 1.5, 15000);
  }

  // ---- activity and other annotators ---------------------------------------------------

  private async loadEvents(): Promise<void> {
    if (this.readOnly) return;
    const events = await get<ReviewEvent[] | { results: ReviewEvent[] }>(`/api/captures/${this.capture.id}/review/events/`).catch(() => null);
    if (!events) return;
    renderEvents(this.el.events, listOf(events));
  }

  private async giveBack(others: Review[], select: HTMLSelectElement): Promise<void> {
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
      void this.loadOtherReviews();
    } catch (err) {
      toast((err as Error).message, "error");
    }
  }

  private async loadOtherReviews(): Promise<void> {
    if (!this.project || this.project.role === "annotator") return;
    const reviews = await get<Review[] | { results: Review[] }>(`/api/captures/${this.capture.id}/reviews/`).catch(() => null);
    if (!reviews) return;
    const others = listOf(reviews).filter((r) => r.annotator.id !== this.me.id);
    if (!others.length) return;
    const select = h(
      "select",
      { class: "select", "data-testid": "review-picker", title: "Whose review to show" },
      h("option", { value: "" }, "My review"),
      ...others.map((r) => h("option", { value: String(r.id) }, `${r.annotator.username} (read-only)`)),
    );
    select.addEventListener("change", () => {
      select.blur();
      this.el.eventsTitle.textContent = select.value ? "Activity (of your own review)" : "Activity";
      const other = others.find((r) => String(r.id) === select.value);
      this.readOnly = other !== undefined;
      this.review = other ?? this.saver.server ?? this.own;
      this.selectedCutId = null;
      giveBack.hidden = other?.status !== "submitted";
      this.refresh();
    });
    const giveBack = h("button", { class: "btn", hidden: true, "data-testid": "return-review", title: "Send this submitted review back to its annotator with a comment", onclick: () => void this.giveBack(others, select) }, "Return…");
    clear(this.el.reviewPicker, select, giveBack);
  }
}
