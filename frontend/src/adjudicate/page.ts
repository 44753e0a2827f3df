// Adjudication on the shared timeline (reviewers, admins): the 3D player and the keys of
// the review page, one tier per submitted review with the gold tier on top, disagreements
// marked where they are. Click a tier's cut or segment to take it into gold; drag gold
// cuts (they snap to the tiers' cuts); undo/redo; saving refuses a stale version (409).

import { ApiError, api, get } from "../api/client";
import type { Capture, LabelChoice } from "../api/types";
import { addCut, fromSpans, moveCut, removeCut, sameDraft, segmentAt, setLabel, toSpans, type Draft } from "../library/gold";
import { annotationExportMenu, captureAnnotationsUrl } from "../library/annotationExport";
import { topbar } from "../library/nav";
import { openImportDialog } from "../review/annotationsDialog";
import type { Adjudication, Span } from "../library/types";
import { PlaybackController } from "../player/playback";
import { SkeletonView } from "../player/skeletonView";
import { helpOverlay } from "../review/commands";
import { FrameStore, loadFrames } from "../review/frames";
import { labelForHotkey, pageCommand } from "../review/keys";
import { NUDGE_STEP, type Command } from "../review/keymap";
import { openPalette } from "../review/palette";
import { formatTimecode, GotoError, parseGoto } from "../review/timecode";
import { formatTime } from "../review/timescale";
import { clear, dialog, h, toast } from "../ui/dom";
import { promptLine } from "../ui/prompt";
import { VideoDock } from "../video/dock";
import { agreementBox } from "./agreement";
import { back, cutMarks, forward, labelConflicts, push, start, unlabelledGold, type Timeline } from "./marks";
import { Tiers } from "./tiers";
import "./adjudicate.css";

export async function renderAdjudication(root: HTMLElement, captureId: number): Promise<() => void> {
  const [data, capture] = await Promise.all([
    get<Adjudication>(`/api/captures/${captureId}/adjudication/`),
    get<Capture>(`/api/captures/${captureId}/`),
  ]);
  const page = new AdjudicationPage(root, data, capture);
  return () => page.dispose();
}

type Review = Adjudication["reviews"][number];

/** The review page's keys, as they act on the gold tier here. */
const ADJ_HELP: [string, string][] = [
  ["Space", "play / pause"],
  ["← / →, , / .", "1 or 10 frames back / forward"],
  ["Shift + ← / →", "jump to the previous / next cut of any tier"],
  ["Home / End", "first / last frame"],
  ["U / Shift+U", "next / previous unlabelled gold segment"],
  ["G", "go to a frame or a timecode (HH:MM:SS:FF), typed"],
  ["Alt + ← / →", "nudge the selected gold cut one frame earlier / later"],
  ["Alt + Shift + ← / →", `nudge the selected gold cut ${NUDGE_STEP} frames`],
  ["[ / ]", "slower / faster"],
  ["I", "insert a gold cut at the playhead"],
  ["D or Delete", "delete the selected gold cut"],
  ["1 – 9, /", "label the gold segment under the playhead (/ opens the palette)"],
  ["0 or Backspace", "clear that gold segment's label"],
  ["Z / Shift+Z", "undo / redo"],
  ["+ / −, wheel", "zoom the tiers"],
  ["Click a tier's cut or segment", "take it into gold"],
  ["Drag a gold cut", "move it; it snaps to the tiers' cuts"],
  ["?", "show / hide this help"],
];

class AdjudicationPage {
  private history: Timeline<Draft>;
  private saved: Draft | null;
  private source: number | null;
  private readonly playback: PlaybackController;
  private selectedCut: number | null = null;
  private readonly reviews: Review[];
  private readonly labels: LabelChoice[];
  private readonly store: FrameStore;
  private readonly abort = new AbortController();
  private readonly player: SkeletonView | null = null;
  private readonly tiers: Tiers;
  private readonly videos: VideoDock;
  private readonly el: Record<string, HTMLElement> = {};
  private readonly onKey = (e: KeyboardEvent) => {
    const command = pageCommand(e);
    if (command) this.command(command);
  };
  private readonly onResize = () => this.refresh();

  constructor(
    root: HTMLElement,
    private data: Adjudication,
    private readonly capture: Capture,
  ) {
    // Only submitted reviews are tiers: in-progress and returned ones are not final.
    this.reviews = data.reviews.filter((r) => r.status === "submitted");
    this.labels = data.labels;
    const gold = data.gold ? fromSpans(data.gold.segments) : { cuts: [], labels: [null] };
    this.history = start(gold);
    this.saved = data.gold ? gold : null;
    this.source = data.gold?.source_review ?? null;
    this.playback = new PlaybackController(capture.fps!, capture.n_frames!, 0, () => this.refresh());
    clear(root, this.layout());
    // Reference videos sit at the top of the side column and follow the playback clock.
    this.videos = new VideoDock(this.el.panel, { captureId: capture.id, fps: capture.fps!, nFrames: capture.n_frames!, playback: this.playback });
    this.el.panel.prepend(this.videos.root);
    try {
      this.player = new SkeletonView(this.el.viewport, capture.skeleton!);
    } catch (err) {
      this.el.viewport.append(h("div", { class: "no-webgl" }, `3D view unavailable (${err instanceof Error ? err.message : "no WebGL"}).`));
    }
    this.store = new FrameStore(capture.n_frames!, capture.n_joints || capture.skeleton!.joints.length);
    void loadFrames(capture.id, this.store, 0, () => this.showPose(true), this.abort.signal);
    this.tiers = new Tiers(this.el.tiers, {
      seek: (f) => this.seekTo(f),
      takeCut: (f) => this.takeCut(f),
      takeSegment: (s) => this.takeSegment(s),
      selectGoldCut: (i) => {
        this.selectedCut = i;
        this.seekTo(this.draft.cuts[i]);
      },
      moveGoldCut: (i, f) => {
        this.selectedCut = i;
        this.edit(moveCut(this.draft, i, f, this.n), `moved a gold cut to ${f}`);
      },
      snapTargets: () => this.reviews.flatMap((r) => r.cuts),
    }, capture.n_frames!);
    document.addEventListener("keydown", this.onKey);
    window.addEventListener("resize", this.onResize);
    this.refresh();
  }

  dispose(): void {
    this.abort.abort();
    this.videos.dispose();
    this.playback.dispose();
    document.removeEventListener("keydown", this.onKey);
    window.removeEventListener("resize", this.onResize);
    this.player?.dispose();
  }

  private get n(): number {
    return this.capture.n_frames!;
  }

  private get draft(): Draft {
    return this.history.present;
  }

  private frame(): number {
    return this.playback.frame;
  }

  // ---- layout --------------------------------------------------------------------------

  private layout(): HTMLElement {
    const el = this.el;
    const button = (id: string, text: string, title: string, action: () => void, extra = "") =>
      (el[id] = h("button", { class: `btn ${extra}`, title, "data-testid": id, onclick: (e: Event) => { (e.currentTarget as HTMLElement).blur(); action(); } }, text));
    el.viewport = h("div", { class: "viewport adj-viewport", "data-testid": "viewport" });
    el.hud = h("div", { class: "hud-frame", "data-testid": "hud-frame" });
    el.status = h("span", { class: "muted", "data-testid": "gold-status" });
    el.editor = h("div", { class: "adj-side", "data-testid": "gold-editor" });
    el.tiers = h("div", { class: "tiers", "data-testid": "adj-tracks" });
    el.agreement = agreementBox(this.data.agreement);
    const uses = this.reviews.map((r) => h("button", { class: "btn btn-small", "data-testid": `use-${r.annotator.username}`, title: "Replace the gold draft with this review", onclick: () => this.useReview(r) }, `Start gold from ${r.annotator.username}`));
    const legend = h("div", { class: "adj-legend muted small" },
      h("span", { class: "tier-cut-key mark-agreed" }), " all agree ",
      h("span", { class: "tier-cut-key mark-shifted" }), " matched but further apart than the tolerance ",
      h("span", { class: "tier-cut-key mark-lone" }), " only some annotators ",
      h("span", { class: "tier-conflict-key" }), " labels differ");
    return h(
      "div",
      { class: "list-page adj-page" },
      // Only reviewers and admins adjudicate: their links include the team.
      topbar([["Captures", "/"], [this.data.capture.name, `/captures/${this.capture.id}/`], ["Adjudication", null]], this.data.capture.project, "reviewer"),
      h(
        "main",
        { class: "list-main adj-main" },
        h("div", { class: "adj-head" }, h("h1", { class: "page-title", "data-testid": "adj-title" }, `Adjudicate ${this.data.capture.name}`), el.agreement),
        h(
          "div",
          { class: "adj-work" },
          h("div", { class: "adj-stage" }, el.viewport, h("div", { class: "hud adj-hud" }, el.hud)),
          (el.panel = h(
            "div",
            { class: "adj-panel" },
            h("div", { class: "adj-actions" }, button("play", "Play", "Play / pause (Space)", () => this.command({ kind: "play" })), button("undo", "Undo", "Undo (Z, Ctrl+Z)", () => this.command({ kind: "undo" })), button("redo", "Redo", "Redo (Shift+Z)", () => this.command({ kind: "redo" })), button("save-gold", "Save gold version", "Save the gold version", () => void this.save(), "btn-primary"), el.status),
            h("div", { class: "adj-actions" }, button("import-gold", "Import into gold…", "Make the gold version a CSV, ELAN or Label Studio file's segments", () => void this.importGold()), annotationExportMenu((f) => captureAnnotationsUrl(this.capture.id, f, "all"), "every review and gold", "Download every review and the gold version for ELAN, Label Studio or a spreadsheet", "export-annotations")),
            el.editor,
            h("div", { class: "adj-uses" }, ...uses),
            legend,
          )),
        ),
        el.tiers,
      ),
    );
  }

  // ---- drawing -------------------------------------------------------------------------

  private refresh(): void {
    const spans = toSpans(this.draft, this.n);
    const tolerance = Math.round(this.data.agreement.tolerance_s * this.capture.fps!);
    const marks = cutMarks(this.reviews.map((r) => r.cuts), tolerance);
    this.tiers.update({
      nFrames: this.n, fps: this.capture.fps!, colors: new Map(this.labels.map((l) => [l.name, l.color])),
      gold: { cuts: this.draft.cuts, segments: spans },
      tiers: this.reviews.map((r, i) => ({ id: String(r.id), name: r.annotator.username, cuts: r.cuts, marks: marks[i], segments: r.segments })),
      conflicts: labelConflicts(this.reviews.map((r) => r.segments), this.n),
      playhead: this.frame(), selectedCut: this.selectedCut,
    });
    this.drawEditor(spans);
    const dirty = !this.saved || !sameDraft(this.draft, this.saved);
    this.el.status.textContent = dirty ? "Unsaved changes" : "Saved";
    this.el["save-gold"].toggleAttribute("disabled", !dirty);
    this.el.undo.toggleAttribute("disabled", !this.history.past.length);
    this.el.redo.toggleAttribute("disabled", !this.history.future.length);
    this.el.play.textContent = this.playback.playing ? "Pause" : "Play";
    this.showPose(false);
  }

  /** The labels offered for new gold segments: retired ones stay only where they are. */
  private activeLabels(): LabelChoice[] {
    return this.labels.filter((l) => !l.retired);
  }

  private drawEditor(spans: Span[]): void {
    const index = segmentAt(this.draft, this.frame());
    const s = spans[index];
    const select = h(
      "select",
      { class: "select", "data-testid": "gold-label", "aria-label": "label of the gold segment under the playhead" },
      h("option", { value: "", selected: s.label === null }, "(unlabelled)"),
      // A retired label is offered only on the segment that already carries it.
      ...this.labels
        .filter((l) => !l.retired || s.label === l.name)
        .map((l) => h("option", { value: l.name, selected: s.label === l.name }, l.retired ? `${l.name} (retired)` : l.hotkey ? `${l.name} (${l.hotkey})` : l.name)),
    );
    select.addEventListener("change", () => {
      select.blur();
      this.edit(setLabel(this.draft, index, select.value || null), `labelled gold segment ${index + 1}`);
    });
    const cut = this.selectedCut !== null ? this.draft.cuts[this.selectedCut] : undefined;
    clear(
      this.el.editor,
      h("div", { "data-testid": "gold-segment" }, h("b", {}, `Gold segment ${index + 1} of ${spans.length}`), ` · frames ${s.start}–${s.stop}`),
      h("div", { class: "filters" }, select),
      cut !== undefined ? h("div", { class: "muted", "data-testid": "gold-selected-cut" }, `Selected gold cut at ${cut} (D deletes; drag or Alt+←/→ moves)`) : h("div", { class: "muted" }, "I inserts a gold cut at the playhead; 1–9 or / label the gold segment under it."),
    );
  }

  private showPose(force: boolean): void {
    const frame = this.frame();
    this.el.hud.textContent = `Frame ${frame} / ${this.n - 1} · ${formatTime(frame, this.capture.fps!)}`;
    if (!this.player) return;
    const shown = this.store.has(frame) ? frame : this.store.nearestLoaded(frame);
    if (shown !== null && (force || shown === frame)) this.player.setPose(this.store.pose(shown));
  }

  // ---- gold edits ----------------------------------------------------------------------

  private edit(next: Draft, what: string): void {
    if (sameDraft(next, this.draft)) {
      toast(`Gold unchanged (${what}).`);
      return this.refresh();
    }
    this.history = push(this.history, next);
    this.refresh();
  }

  private takeCut(frame: number): void {
    this.edit(addCut(this.draft, frame, this.n), `cut at ${frame} is already in gold`);
    this.seekTo(frame);
  }

  /** The segment's bounds become gold cuts and the gold segment between them takes its label. */
  private takeSegment(s: Span): void {
    let next = addCut(addCut(this.draft, s.start, this.n), s.stop, this.n);
    next = setLabel(next, segmentAt(next, s.start), s.label);
    this.edit(next, `segment ${s.start}–${s.stop} is already gold`);
    this.seekTo(s.start);
  }

  private useReview(r: Review): void {
    this.source = r.id;
    this.selectedCut = null;
    this.edit(fromSpans(r.segments), `gold already equals ${r.annotator.username}'s version`);
  }

  private labelUnderPlayhead(name: string | null): void {
    const index = segmentAt(this.draft, this.frame());
    this.edit(setLabel(this.draft, index, name), "same label");
  }

  /** Import a file as the gold version (review/annotationsDialog.ts); the page then shows
   * the gold version the server saved, as after a save. */
  private async importGold(): Promise<void> {
    await openImportDialog({
      captureId: this.capture.id,
      into: "gold",
      version: () => this.data.gold?.version ?? 0,
      imported: (_answer, summary) => void this.reloadGold(summary),
    });
  }

  private async reloadGold(summary: string): Promise<void> {
    this.data = await get<Adjudication>(`/api/captures/${this.capture.id}/adjudication/`);
    if (this.data.gold) {
      this.saved = fromSpans(this.data.gold.segments);
      this.history = push(this.history, this.saved);
    }
    toast(`${summary} Gold version ${this.data.gold?.version ?? ""} saved.`);
    this.refresh();
  }

  private async save(): Promise<void> {
    const body = { cuts: this.draft.cuts, labels: this.draft.labels, version: this.data.gold?.version ?? 0, source_review: this.source };
    try {
      this.data = await api<Adjudication>("PUT", `/api/captures/${this.capture.id}/adjudication/`, body);
      this.saved = fromSpans(this.data.gold!.segments);
      toast(`Gold version ${this.data.gold!.version} saved.`);
      const box = agreementBox(this.data.agreement);
      this.el.agreement.replaceWith(box);
      this.el.agreement = box;
    } catch (err) {
      if (err instanceof ApiError && err.status === 409) await this.onConflict(err.body as { gold: Adjudication["gold"] });
      else toast((err as Error).message, "error");
    }
    this.refresh();
  }

  /** Someone saved gold meanwhile: show theirs now; undo brings this draft back to save over it. */
  private async onConflict(body: { gold: Adjudication["gold"] }): Promise<void> {
    const theirs = body.gold;
    this.data = { ...this.data, gold: theirs };
    if (!theirs) return;
    this.saved = fromSpans(theirs.segments);
    this.history = push(this.history, this.saved);
    this.refresh();
    await dialog("The gold version changed meanwhile", [
      h("p", {}, `${theirs.adjudicator ?? "Someone"} saved gold version ${theirs.version} while you were editing. It is shown now.`),
      h("p", {}, "Your draft was not saved. Undo (Z) brings it back; saving it then replaces their version."),
    ]);
  }

  // ---- playback and keys ---------------------------------------------------------------

  private seekTo(frame: number): void {
    this.playback.seek(frame);
    this.refresh();
  }

  /** Ask for a frame or a timecode and go there; a bad answer is named, the playhead stays. */
  private async askGoto(): Promise<void> {
    const fps = this.capture.fps!;
    const last = `${this.n - 1} (${formatTimecode(this.n - 1, fps)})`;
    const text = await promptLine("Go to", `A frame number (0 to ${last}) or a timecode HH:MM:SS:FF at ${fps} fps.`, "Go", formatTimecode(this.frame(), fps));
    if (text === null) return;
    try {
      this.playback.seekAndPause(parseGoto(text, fps, this.n));
    } catch (err) {
      if (!(err instanceof GotoError)) throw err;
      toast(err.message, "error");
    }
    this.refresh();
  }

  private toggleHelp(): void {
    const open = document.querySelector(".adj-help");
    if (open) return open.remove();
    const box = helpOverlay(ADJ_HELP, () => box.remove(), "adj-help");
    document.body.append(box);
  }

  private command(c: Command): void {
    const frame = this.frame();
    const all = [...new Set([...this.draft.cuts, ...this.reviews.flatMap((r) => r.cuts)])].sort((a, b) => a - b);
    switch (c.kind) {
      case "play":
        this.playback.toggle();
        break;
      case "step":
        return this.seekTo(frame + c.frames);
      case "home":
        return this.seekTo(0);
      case "end":
        return this.seekTo(this.n - 1);
      case "jump": {
        const target = c.direction > 0 ? all.find((f) => f > frame) : [...all].reverse().find((f) => f < frame);
        if (target !== undefined) this.seekTo(target);
        return;
      }
      case "unlabelled": {
        const target = unlabelledGold(this.draft, frame, c.direction);
        if (target === null) toast(`No unlabelled gold segment ${c.direction > 0 ? "after" : "before"} frame ${frame}.`);
        else this.seekTo(target);
        return;
      }
      case "goto":
        return void this.askGoto();
      case "nudge": {
        if (this.selectedCut === null) return void toast("Select a gold cut first: click it on the gold tier.");
        const index = this.selectedCut;
        const to = this.draft.cuts[index] + c.frames;
        this.edit(moveCut(this.draft, index, to, this.n), `the gold cut cannot move past its neighbours`);
        return this.seekTo(this.draft.cuts[index]);
      }
      case "speed":
        this.playback.nudgeSpeed(c.direction);
        break;
      case "zoom":
        this.tiers.zoom(c.factor, frame);
        return;
      case "undo":
        this.history = back(this.history);
        break;
      case "redo":
        this.history = forward(this.history);
        break;
      case "insert":
        return this.edit(addCut(this.draft, frame, this.n), `a gold cut is already at ${frame}`);
      case "delete":
        if (this.selectedCut === null) toast("Select a gold cut first: click it on the gold tier.");
        else {
          const index = this.selectedCut;
          this.selectedCut = null;
          this.edit(removeCut(this.draft, index), "no such cut");
        }
        return;
      case "label": {
        const label = labelForHotkey(this.activeLabels(), c.hotkey);
        if (label) this.labelUnderPlayhead(label.name);
        else toast(`No label has hotkey ${c.hotkey}.`);
        return;
      }
      case "clearLabel":
        return this.labelUnderPlayhead(null);
      case "palette":
        openPalette(this.activeLabels(), (name) => this.labelUnderPlayhead(name));
        return;
      case "help":
        this.toggleHelp();
        return;
      case "escape":
        if (document.querySelector(".adj-help")) this.toggleHelp();
        this.selectedCut = null;
        break;
      default:
        return;
    }
    this.refresh();
  }
}

