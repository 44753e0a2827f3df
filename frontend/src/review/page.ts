// The review page: skeleton player on top, timeline lanes under it, labels and the
// activity log at the side. Every edit is applied on screen at once and saved through
// the API straight away (saver.ts); undo/redo are edits too, so the audit log is complete.

import { get, post } from "../api/client";
import type { Capture, Cut, Label, Me, Project, Review, ReviewEvent, Signal, SignalResponse } from "../api/types";
import { advance, frameOf, nextSpeed, seek, SPEEDS, togglePlay, type Playback } from "../player/clock";
import { SkeletonView } from "../player/skeletonView";
import { clear, dialog, formatDuration, h, toast } from "../ui/dom";
import { icon } from "../ui/icons";
import { FrameStore, loadFrames } from "./frames";
import { changeFor, emptyHistory, record, redo, undo, type Change, type History } from "./history";
import { commandFor, HELP, isTypingTarget, type Command } from "./keymap";
import { Saver } from "./saver";
import { applyEdit, clampFrame, describeDifferences, EditError, FATE_TEXT, neighbourCut, segmentAt, type Edit } from "./state";
import { eventDetail } from "./events";
import { Timeline } from "./timeline";
import { formatTime } from "./timescale";

export async function renderReview(root: HTMLElement, captureId: number): Promise<() => void> {
  clear(root, h("div", { class: "loading-page" }, "Opening capture…"));
  const [capture, me, projects] = await Promise.all([
    get<Capture>(`/api/captures/${captureId}/`),
    get<Me>("/api/me/"),
    get<Project[] | { results: Project[] }>("/api/projects/"),
  ]);
  const project = listOf(projects).find((p) => p.id === capture.project);
  if (capture.status !== "ready" || !capture.skeleton) return renderNotReady(root, capture);
  const [review, signal] = await Promise.all([
    post<Review>(`/api/captures/${captureId}/review/`),
    get<SignalResponse>(`/api/captures/${captureId}/signal/?max_points=4000`).catch(() => null),
  ]);
  const page = new ReviewPage(root, capture, me, project ?? null, review, signal?.signals ?? []);
  return () => page.dispose();
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
  private readonly saver: Saver;
  private readonly store: FrameStore;
  private readonly player: SkeletonView | null;
  private readonly timeline: Timeline;
  private readonly abort = new AbortController();
  private readonly labels: Label[];
  private readonly el: Record<string, HTMLElement> = {};
  private readonly onKey = (e: KeyboardEvent) => this.handleKey(e);

  constructor(
    root: HTMLElement,
    private readonly capture: Capture,
    private readonly me: Me,
    private readonly project: Project | null,
    review: Review,
    private readonly signals: Signal[],
  ) {
    this.review = review;
    this.own = review;
    this.labels = project?.labels ?? [];
    this.playback = { position: 0, playing: false, speed: 1, fps: capture.fps, nFrames: capture.n_frames, loop: null };
    this.saver = new Saver(capture.id, review, {
      saved: (r, idle, renamed) => this.onSaved(r, idle, renamed),
      conflict: (r, unsaved, message) => void this.onConflict(r, unsaved, message),
      failed: (r, unsaved, message) => this.onFailed(r, unsaved, message),
      busy: (n) => this.showSaveState(n),
    });
    clear(root, this.build());
    this.player = this.makePlayer();
    this.timeline = new Timeline(this.el.timeline, {
      seek: (f) => this.seekTo(f),
      selectCut: (id) => this.select(id),
      acceptCut: (id) => this.perform({ kind: "fate", cutId: id, fate: "accepted" }),
      moveCut: (id, frame) => this.perform({ kind: "move", cutId: id, frame }),
      insertAt: (frame) => this.perform({ kind: "insert", frame, tempId: this.nextTempId-- }),
      setLoop: (range) => {
        this.playback = range ? seek({ ...this.playback, loop: range }, range.start) : { ...this.playback, loop: null };
        this.refresh();
      },
    });
    this.store = new FrameStore(capture.n_frames, capture.n_joints || capture.skeleton!.joints.length);
    const started = performance.now();
    void loadFrames(capture.id, this.store, 0, () => this.onFramesLoaded(started), this.abort.signal);
    document.addEventListener("keydown", this.onKey);
    this.refresh();
    void this.loadEvents();
    void this.loadOtherReviews();
  }

  dispose(): void {
    this.abort.abort();
    cancelAnimationFrame(this.raf);
    document.removeEventListener("keydown", this.onKey);
    this.player?.dispose();
  }

  // ---- layout --------------------------------------------------------------------------

  private build(): HTMLElement {
    const c = this.capture;
    const btn = (id: string, text: string | Node, title: string, action: () => void, extra = "") =>
      (this.el[id] = h("button", { class: `btn ${extra}`, title, "data-testid": id, onclick: (e: Event) => {
        // Keys belong to the editor, not to the last button clicked (Space would click it again).
        (e.currentTarget as HTMLElement).blur();
        action();
      } }, text));
    this.el.viewport = h("div", { class: "viewport", "data-testid": "viewport" });
    this.el.hudFrame = h("div", { class: "hud-frame", "data-testid": "hud-frame" });
    this.el.hudTime = h("div", { class: "hud-time", "data-testid": "hud-time" });
    this.el.hudState = h("div", { class: "hud-state", "data-testid": "hud-state" });
    this.el.loading = h("div", { class: "hud-loading", "data-testid": "frames-loading" });
    this.el.loadingBar = h("div", { class: "hud-loading-bar" });
    this.el.loading.append(this.el.loadingBar);
    this.el.timeline = h("div", { class: "timeline", "data-testid": "timeline" });
    this.el.saveState = h("span", { class: "save-state", "data-testid": "save-state" }, "Saved");
    this.el.reviewPicker = h("span", { class: "review-picker" });
    this.el.banner = h("div", { class: "readonly-banner", hidden: true, "data-testid": "readonly-banner" });
    this.el.labels = h("div", { class: "label-list", "data-testid": "labels" });
    this.el.selection = h("div", { class: "selection", "data-testid": "selection" });
    this.el.stats = h("div", { class: "stats", "data-testid": "stats" });
    this.el.events = h("ol", { class: "events", "data-testid": "events" });
    this.el.speed = h(
      "select",
      { class: "select", title: "Playback speed ([ and ])", "data-testid": "speed", onchange: (e: Event) => {
        const select = e.target as HTMLSelectElement;
        select.blur();
        this.setSpeed(Number(select.value));
      } },
      ...SPEEDS.map((s) => h("option", { value: s, selected: s === 1 }, `${s}×`)),
    );
    return h(
      "div",
      { class: "review-page" },
      h(
        "header",
        { class: "topbar" },
        h("a", { class: "brand", href: "/" }, "Cutroom"),
        h("nav", { class: "crumbs" }, h("a", { href: "/" }, "Captures"), h("span", {}, "/"), h("strong", { "data-testid": "capture-name" }, c.name)),
        h("span", { class: "meta" }, `${c.n_frames.toLocaleString()} frames · ${c.fps} fps · ${formatDuration(c.duration ?? c.n_frames / c.fps)} · ${c.format.toUpperCase()}`),
        h("span", { class: "spacer" }),
        this.el.reviewPicker,
        this.el.saveState,
        btn("submit", "Submit review", "Mark this review finished; it can no longer be edited", () => void this.submit(), "btn-primary"),
        h("button", { class: "btn btn-ghost", title: "Keyboard shortcuts (?)", "data-testid": "help-button", onclick: () => this.toggleHelp() }, "?"),
        h("span", { class: "user" }, this.me.username),
      ),
      this.el.banner,
      h(
        "div",
        { class: "workspace" },
        h("div", { class: "stage" }, this.el.viewport, h("div", { class: "hud" }, this.el.hudFrame, this.el.hudTime, this.el.hudState), this.el.loading),
        h(
          "aside",
          { class: "side" },
          h("section", {}, h("h3", {}, "Labels"), this.el.labels),
          h("section", {}, h("h3", {}, "Selection"), this.el.selection),
          h("section", {}, h("h3", {}, "Review"), this.el.stats),
          h("section", { class: "grow" }, (this.el.eventsTitle = h("h3", {}, "Activity")), this.el.events),
        ),
      ),
      h(
        "div",
        { class: "transport" },
        h(
          "div",
          { class: "group" },
          btn("prev-cut", icon("prevCut"), "Previous cut (Shift+←)", () => this.command({ kind: "jump", direction: -1 })),
          btn("step-back", icon("stepBack"), "Previous frame (←)", () => this.command({ kind: "step", frames: -1 })),
          btn("play", icon("play"), "Play / pause (Space)", () => this.command({ kind: "play" }), "btn-play"),
          btn("step-forward", icon("stepForward"), "Next frame (→)", () => this.command({ kind: "step", frames: 1 })),
          btn("next-cut", icon("nextCut"), "Next cut (Shift+→)", () => this.command({ kind: "jump", direction: 1 })),
          this.el.speed,
          btn("loop", "Loop", "Loop the segment under the playhead (L)", () => this.command({ kind: "loop" })),
          btn("follow", "Follow", "Camera follows the root", () => this.toggleFollow(), "active"),
        ),
        h(
          "div",
          { class: "group" },
          btn("accept", "Accept", "Accept the selected candidate (A)", () => this.command({ kind: "accept" })),
          btn("delete", "Delete", "Delete the selected cut (D)", () => this.command({ kind: "delete" })),
          btn("insert", "Insert", "Insert a cut at the playhead (I)", () => this.command({ kind: "insert" })),
          btn("undo", "Undo", "Undo (Z)", () => this.command({ kind: "undo" })),
          btn("redo", "Redo", "Redo (Shift+Z)", () => this.command({ kind: "redo" })),
        ),
        h(
          "div",
          { class: "group" },
          btn("zoom-out", "−", "Zoom out (-)", () => this.timeline.zoom(1.5, this.frame())),
          btn("zoom-fit", "Fit", "Show the whole take", () => this.timeline.zoom(1e9)),
          btn("zoom-in", "+", "Zoom in (+)", () => this.timeline.zoom(1 / 1.5, this.frame())),
        ),
      ),
      this.el.timeline,
    );
  }

  private makePlayer(): SkeletonView | null {
    try {
      return new SkeletonView(this.el.viewport, this.capture.skeleton!);
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
    for (const id of ["accept", "delete", "insert", "submit"]) this.el[id].toggleAttribute("disabled", locked);
    this.el.submit.textContent = this.review.status === "submitted" ? "Submitted" : "Submit review";
    const banner = this.readOnly ? `Viewing ${this.review.annotator.username}'s review — read-only.` : locked ? "You submitted this review — read-only." : "";
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
    this.renderLabels();
    this.renderSelection();
    const counts: Record<string, number> = { pending: 0, accepted: 0, moved: 0, inserted: 0, deleted: 0 };
    for (const cut of this.review.cuts) counts[cut.origin === "inserted" && cut.fate !== "deleted" ? "inserted" : cut.fate]++;
    const labelled = this.review.segments.filter((s) => s.label).length;
    clear(
      this.el.stats,
      h("div", { class: "stat-grid" }, ...Object.entries(counts).map(([k, v]) => h("div", { class: `stat stat-${k}` }, h("b", {}, v), h("span", {}, k)))),
      h("div", { class: "muted" }, `${labelled} of ${this.review.segments.length} segments labelled · version ${this.review.version} · ${this.review.status.replace("_", " ")}`),
    );
  }

  private renderLabels(): void {
    const segment = segmentAt(this.review.segments, this.frame());
    if (!this.labels.length) {
      clear(this.el.labels, h("p", { class: "muted" }, "This project has no labels yet."));
      return;
    }
    clear(
      this.el.labels,
      ...this.labels.map((label) =>
        h(
          "button",
          {
            class: `label-chip${segment?.label === label.name ? " current" : ""}`,
            "data-testid": `label-${label.name}`,
            disabled: this.locked() !== null,
            title: `Label the segment under the playhead${label.hotkey ? ` (${label.hotkey})` : ""}`,
            onclick: (e: Event) => {
              (e.currentTarget as HTMLElement).blur();
              this.labelCurrent(label.name);
            },
          },
          h("span", { class: "swatch", style: `background:${label.color}` }),
          h("span", { class: "name" }, label.name),
          label.hotkey ? h("kbd", {}, label.hotkey) : null,
        ),
      ),
    );
  }

  private renderSelection(): void {
    const cut = this.selectedCut();
    const segment = segmentAt(this.review.segments, this.frame());
    const fps = this.capture.fps;
    clear(
      this.el.selection,
      cut
        ? h(
            "div",
            { class: "sel-cut", "data-testid": "selected-cut" },
            h("div", {}, h("b", {}, `Cut at ${cut.frame}`), ` · ${formatTime(cut.frame, fps)}`),
            h("div", { class: `fate fate-${cut.fate}` }, cut.origin === "inserted" ? "inserted" : FATE_TEXT[cut.fate]),
            cut.candidate_frame !== null && cut.candidate_frame !== cut.frame ? h("div", { class: "muted" }, `proposed at ${cut.candidate_frame}`) : null,
            cut.confidence !== null ? h("div", { class: "muted" }, `confidence ${(cut.confidence * 100).toFixed(0)} %`) : null,
          )
        : h("div", { class: "muted" }, "No cut selected: click one, or Shift+←/→."),
      segment
        ? h(
            "div",
            { class: "sel-seg", "data-testid": "current-segment" },
            h("b", {}, `Segment ${segment.index + 1}`),
            ` · ${segment.start}–${segment.stop} · ${formatDuration((segment.stop - segment.start) / fps)}`,
            h("div", {}, segment.label ? `labelled ${segment.label}` : h("span", { class: "muted" }, "unlabelled")),
            !segment.label && segment.suggested_label ? h("div", { class: "muted", "data-testid": "suggested-label" }, `suggested: ${segment.suggested_label} (S accepts)`) : null,
          )
        : null,
    );
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

  private async submit(): Promise<void> {
    if (this.locked() || this.saver.pending) return;
    try {
      this.review = await post<Review>(`/api/captures/${this.capture.id}/review/submit/`, { version: this.saver.server.version });
      this.saver.server = this.review;
      this.history = emptyHistory();
      toast("Review submitted.");
      void this.loadEvents();
    } catch (err) {
      toast(`Not submitted: ${err instanceof Error ? err.message : String(err)}`, "error");
    }
    this.refresh();
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
    }
  }

  private async onConflict(current: Review, unsaved: string[], message: string): Promise<void> {
    const changes = describeDifferences(this.review, current);
    this.review = current;
    this.history = emptyHistory();
    this.refresh();
    await dialog("This review changed elsewhere", [
      h("p", {}, message),
      h("p", {}, "The current version is shown now. What changed:"),
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
  }

  private timelineModel() {
    return {
      nFrames: this.capture.n_frames, fps: this.capture.fps, signals: this.signals, cuts: this.review.cuts,
      segments: this.review.segments, labels: this.labels, playhead: this.frame(),
      selectedCutId: this.selectedCutId, loop: this.playback.loop, readOnly: this.locked() !== null,
    };
  }

  // ---- commands ------------------------------------------------------------------------

  private handleKey(e: KeyboardEvent): void {
    if (isTypingTarget(e.target) || document.querySelector(".modal-backdrop:not(.help)")) return;
    const command = commandFor(e);
    if (!command) return;
    e.preventDefault();
    this.command(command);
  }

  private command(c: Command): void {
    const frame = this.frame();
    switch (c.kind) {
      case "play":
        this.playback = togglePlay(this.playback);
        this.lastTick = performance.now();
        if (this.playback.playing) this.raf = requestAnimationFrame(this.tick);
        break;
      case "step":
        this.playback = { ...seek(this.playback, clampFrame(frame + c.frames, this.capture.n_frames)), playing: false };
        this.timeline.reveal(this.frame());
        break;
      case "jump": {
        const cut = neighbourCut(this.review.cuts, frame, c.direction);
        if (cut) {
          this.playback = { ...seek(this.playback, cut.frame), playing: false };
          this.selectedCutId = cut.id;
          this.timeline.reveal(cut.frame);
        }
        break;
      }
      case "accept":
      case "delete": {
        const cut = this.selectedCut();
        if (!cut) toast("Select a cut first: click it, or jump to it with Shift+←/→.");
        // Accepting a kept cut would only rewrite its fate (and lose "moved"): say so instead.
        else if (c.kind === "accept" && cut.fate !== "pending") toast(`The cut at ${cut.frame} is already kept (${cut.origin === "inserted" ? "inserted" : cut.fate}).`);
        else this.perform({ kind: "fate", cutId: cut.id, fate: c.kind === "accept" ? "accepted" : "deleted" });
        if (cut && c.kind === "delete") this.selectedCutId = null;
        break;
      }
      case "insert":
        this.perform({ kind: "insert", frame, tempId: this.nextTempId-- });
        break;
      case "label": {
        const label = this.labels.find((l) => l.hotkey === c.hotkey) ?? (this.labels.some((l) => l.hotkey) ? undefined : this.labels[Number(c.hotkey) - 1]);
        if (label) this.labelCurrent(label.name);
        else toast(`No label has hotkey ${c.hotkey}.`);
        break;
      }
      case "clearLabel":
        this.labelCurrent(null);
        break;
      case "acceptSuggestion": {
        const suggested = segmentAt(this.review.segments, frame)?.suggested_label;
        if (suggested) this.labelCurrent(suggested);
        else toast("No suggested label for the segment under the playhead.");
        break;
      }
      case "undo":
        if (!this.locked()) this.replay(undo(this.history, this.review, this.saver.resolve), "undo");
        break;
      case "redo":
        if (!this.locked()) this.replay(redo(this.history, this.review, this.saver.resolve), "redo");
        break;
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
      case "home":
      case "end":
        this.playback = seek(this.playback, c.kind === "home" ? 0 : this.capture.n_frames - 1);
        this.timeline.reveal(this.frame());
        break;
      case "help":
        this.toggleHelp();
        break;
      case "escape":
        if (this.helpOpen) this.toggleHelp();
        else this.selectedCutId = null;
        break;
    }
    this.refresh();
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

  // ---- activity and other annotators ---------------------------------------------------

  private async loadEvents(): Promise<void> {
    if (this.readOnly) return;
    const events = await get<ReviewEvent[] | { results: ReviewEvent[] }>(`/api/captures/${this.capture.id}/review/events/`).catch(() => null);
    if (!events) return;
    const list = listOf(events).slice().reverse();
    clear(
      this.el.events,
      ...list.map((e) =>
        h(
          "li",
          { "data-action": e.action },
          h("span", { class: "ev-action" }, e.action.replace(/_/g, " ")),
          h("span", { class: "ev-detail" }, eventDetail(e)),
          h("time", { datetime: e.created_at, title: e.created_at }, new Date(e.created_at).toLocaleTimeString()),
        ),
      ),
    );
    if (!list.length) this.el.events.append(h("li", { class: "muted" }, "No edits yet."));
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
      this.refresh();
    });
    clear(this.el.reviewPicker, select);
  }
}
