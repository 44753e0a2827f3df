// The timeline: ruler, cut handles, feature signal lane(s), segment bands and an overview
// of the whole take, all on one canvas against one time axis (timescale.ts). No DOM node per
// frame or per cut. What does not move while playing (lanes, cuts, segments) is drawn once
// per view and edit into an offscreen canvas (timelinedraw.ts); each animation frame copies
// it and draws only the playhead, the pointer and the working window on the overview.
// Where a pointer may do what is decided in hits.ts.

import type { Cut, Signal } from "../api/types";
import { denseCuts, hitHandle, isDrag, overviewFrame, overviewX, OVERVIEW, RULER, HANDLES, rows, SEGMENTS, zoneAt, type Rows } from "./hits";
import { isKept } from "./state";
import { clampView, formatTime, frameToX, fullView, openingView, pageFollow, panBy, resize, snapFrame, zoomAround, type View } from "./timescale";
import { cutsInView, drawScene, prepareLane, type Lane, type Scene, type SceneModel } from "./timelinedraw";

export { readableOn } from "./timelinedraw";

/** What the timeline shows (timelinedraw.ts's scene), and whether it may be edited. */
export interface TimelineModel extends SceneModel {
  readOnly: boolean;
}

export interface TimelineHandlers {
  seek(frame: number): void;
  selectCut(id: number | null): void;
  moveCut(id: number, frame: number): void;
  insertAt(frame: number): void;
  setLoop(range: { start: number; stop: number } | null): void;
  restoreCut(id: number): void;
}

type Gesture =
  | { kind: "scrub" }
  | { kind: "overview" }
  | { kind: "pan"; lastX: number }
  | { kind: "loop"; from: number; to: number }
  | { kind: "drag"; cut: Cut; startX: number; moved: boolean; frame: number };

export class Timeline {
  readonly canvas = document.createElement("canvas");
  view: View;
  private model: TimelineModel | null = null;
  private lanes = new Map<Signal, Lane>();
  private gesture: Gesture | null = null;
  private loopPreview: { start: number; stop: number } | null = null;
  private hoverX: number | null = null;
  private hoverY: number | null = null;
  private queued = false;
  private width = 1;
  /** Everything but the playhead, the pointer and the working window, drawn once per `baseKey`. */
  private readonly base = document.createElement("canvas");
  private baseKey: unknown[] = [];
  private dense = false;
  onViewChange: (() => void) | null = null;

  constructor(
    private readonly container: HTMLElement,
    private readonly handlers: TimelineHandlers,
  ) {
    this.canvas.className = "timeline-canvas";
    this.canvas.tabIndex = -1;
    container.appendChild(this.canvas);
    this.view = fullView(1, 1);
    new ResizeObserver(() => this.layoutCanvas()).observe(container);
    this.canvas.addEventListener("pointerdown", (e) => this.onDown(e));
    this.canvas.addEventListener("pointermove", (e) => this.onMove(e));
    this.canvas.addEventListener("pointerup", (e) => this.onUp(e));
    this.canvas.addEventListener("dblclick", (e) => this.onDoubleClick(e));
    this.canvas.addEventListener("wheel", (e) => this.onWheel(e), { passive: false });
    this.canvas.addEventListener("pointerleave", () => {
      this.hoverX = null;
      this.schedule();
    });
  }

  update(model: TimelineModel): void {
    const first = this.model === null || this.model.nFrames !== model.nFrames;
    if (this.model?.signals !== model.signals) this.lanes = new Map(model.signals.map((s) => [s, prepareLane(s)]));
    this.model = model;
    if (first) {
      this.view = openingView(model.nFrames, model.fps, this.width, model.playhead);
      this.layoutCanvas();
    }
    this.schedule();
  }

  setView(view: View): void {
    this.view = clampView(view);
    this.publishView();
    this.onViewChange?.();
    this.schedule();
  }

  zoom(factor: number, aroundFrame?: number): void {
    const x = aroundFrame === undefined ? this.width / 2 : frameToX(this.view, aroundFrame);
    this.setView(zoomAround(this.view, Math.min(Math.max(x, 0), this.width), factor));
  }

  /** Keep the playhead visible while playing or stepping: the working window turns a page when it leaves. */
  reveal(frame: number): void {
    const next = pageFollow(this.view, frame);
    if (next !== this.view) this.setView(next);
  }

  /** The view on the container (data-view-start, data-view-span), for tests and benchmarks. */
  private publishView(): void {
    this.container.dataset.viewStart = String(Math.round(this.view.start));
    this.container.dataset.viewSpan = String(Math.round(this.view.span));
  }

  private rows(): Rows {
    return rows(this.model?.signals.length ?? 1);
  }

  private layoutCanvas(): void {
    this.width = Math.max(this.container.clientWidth, 1);
    const height = this.rows().height;
    const dpr = window.devicePixelRatio || 1;
    for (const canvas of [this.canvas, this.base]) {
      canvas.width = Math.round(this.width * dpr);
      canvas.height = Math.round(height * dpr);
    }
    this.canvas.style.width = `${this.width}px`;
    this.canvas.style.height = `${height}px`;
    this.baseKey = [];
    this.view = clampView(resize(this.view, this.width));
    this.publishView();
    this.draw();
  }

  private schedule(): void {
    if (this.queued) return;
    this.queued = true;
    requestAnimationFrame(() => {
      this.queued = false;
      this.draw();
    });
  }

  draw(): void {
    const m = this.model;
    const ctx = this.canvas.getContext("2d");
    if (!m || !ctx) return;
    const dpr = window.devicePixelRatio || 1;
    const r = this.rows();
    this.drawBase(m, r, dpr);
    ctx.setTransform(1, 0, 0, 1, 0, 0);
    ctx.drawImage(this.base, 0, 0);
    ctx.setTransform(dpr, 0, 0, dpr, 0, 0);
    this.drawCurrentSegment(ctx, m, r);
    this.drawHover(ctx, m, r);
    this.drawPlayhead(ctx, m, r);
    this.drawWindow(ctx, m, r);
    this.drawDragLabel(ctx, r);
  }

  private dragged(): { id: number; frame: number } | null {
    const g = this.gesture;
    return g?.kind === "drag" && g.moved ? { id: g.cut.id, frame: g.frame } : null;
  }

  /** Redraw the offscreen layer only when something it shows changed. */
  private drawBase(m: TimelineModel, r: Rows, dpr: number): void {
    const loop = this.loopPreview ?? m.loop;
    const drag = this.dragged();
    const key = [this.view.start, this.view.span, this.width, dpr, m.signals, m.cuts, m.segments, m.labels, m.selectedCutId,
      loop?.start, loop?.stop, drag?.id, drag?.frame, this.lanes];
    if (key.length === this.baseKey.length && key.every((v, i) => v === this.baseKey[i])) return;
    this.baseKey = key;
    const ctx = this.base.getContext("2d");
    if (!ctx) return;
    ctx.setTransform(dpr, 0, 0, dpr, 0, 0);
    const scene: Scene = { ctx, width: this.width, view: this.view, rows: r, model: { ...m, loop }, lanes: this.lanes, dense: false, drag };
    scene.dense = denseCuts(cutsInView(scene).length, this.width);
    if (scene.dense !== this.dense || this.container.dataset.denseCuts === undefined) {
      this.dense = scene.dense;
      this.container.dataset.denseCuts = String(scene.dense);
    }
    drawScene(scene);
  }

  private x(frame: number): number {
    return frameToX(this.view, frame);
  }

  /** A faint line under the pointer with its frame and time, so a cut can be aimed. */
  private drawHover(ctx: CanvasRenderingContext2D, m: TimelineModel, r: Rows): void {
    if (this.hoverX === null || this.hoverY === null || this.gesture) return;
    const frame = snapFrame(this.view, this.hoverX);
    const x = Math.round(this.x(frame)) + 0.5;
    ctx.strokeStyle = "rgba(255, 255, 255, 0.25)";
    ctx.beginPath();
    ctx.moveTo(x, RULER);
    ctx.lineTo(x, r.segTop + SEGMENTS);
    ctx.stroke();
    ctx.font = "11px ui-monospace, SFMono-Regular, Menlo, monospace";
    ctx.textBaseline = "middle";
    const text = this.hoverText(this.hoverX, this.hoverY, frame, m);
    const w = ctx.measureText(text).width + 8;
    const left = Math.min(Math.max(x + 4, 0), this.width - w);
    ctx.fillStyle = "#2a3340";
    ctx.fillRect(left, RULER + HANDLES + 2, w, 15);
    ctx.fillStyle = "#dfe5ee";
    ctx.fillText(text, left + 4, RULER + HANDLES + 10);
  }

  private hoverText(x: number, y: number, frame: number, m: TimelineModel): string {
    const where = `${frame} · ${formatTime(frame, m.fps)}`;
    if (zoneAt(this.rows(), y) !== "handles") return where;
    if (this.dense) return `${where} · zoom in to grab a cut`;
    const deleted = this.hitDeleted(x, y);
    if (deleted) return `deleted cut at ${deleted.frame} · click to restore`;
    const cut = this.hitCut(x, y);
    if (cut) return m.readOnly ? `cut at ${cut.frame}` : `cut at ${cut.frame} · click to select, drag to move`;
    return where;
  }

  /** The segment under the playhead, outlined (per frame: it changes as the playhead moves). */
  private drawCurrentSegment(ctx: CanvasRenderingContext2D, m: TimelineModel, r: Rows): void {
    const seg = m.segments.find((s) => s.start <= m.playhead && m.playhead < s.stop);
    if (!seg) return;
    const x0 = Math.max(this.x(seg.start), -2);
    const x1 = Math.min(this.x(seg.stop), this.width + 2);
    if (x1 < 0 || x0 > this.width) return;
    ctx.strokeStyle = "#ffffff";
    ctx.lineWidth = 2;
    ctx.strokeRect(x0 + 2, r.segTop + 1, Math.max(x1 - x0 - 4, 1), SEGMENTS - 2);
    ctx.lineWidth = 1;
  }

  private drawPlayhead(ctx: CanvasRenderingContext2D, m: TimelineModel, r: Rows): void {
    const x = Math.round(this.x(m.playhead)) + 0.5;
    ctx.strokeStyle = "#ff5a5f";
    ctx.lineWidth = 1.5;
    ctx.beginPath();
    ctx.moveTo(x, 0);
    ctx.lineTo(x, r.segTop + SEGMENTS);
    ctx.stroke();
    ctx.fillStyle = "#ff5a5f";
    ctx.fillRect(x - 4, 0, 8, 6);
    ctx.lineWidth = 1;
  }

  /** The working window and the playhead on the overview of the whole take. */
  private drawWindow(ctx: CanvasRenderingContext2D, m: TimelineModel, r: Rows): void {
    const x0 = overviewX(this.view.start, this.width, m.nFrames);
    const w = Math.max(overviewX(this.view.start + this.view.span, this.width, m.nFrames) - x0, 3);
    ctx.fillStyle = "rgba(159, 179, 200, 0.12)";
    ctx.fillRect(x0, r.overviewTop, w, OVERVIEW);
    ctx.strokeStyle = "#9fb3c8";
    ctx.strokeRect(x0 + 0.5, r.overviewTop + 0.5, w - 1, OVERVIEW - 1);
    ctx.fillStyle = "#ff5a5f";
    ctx.fillRect(overviewX(m.playhead, this.width, m.nFrames) - 0.5, r.overviewTop, 1.5, OVERVIEW);
  }

  private drawDragLabel(ctx: CanvasRenderingContext2D, r: Rows): void {
    const drag = this.dragged();
    if (!drag) return;
    ctx.fillStyle = "#4fc3f7";
    ctx.font = "600 11px ui-monospace, monospace";
    ctx.fillText(`→ ${drag.frame}`, this.x(drag.frame) + 8, r.handlesTop + HANDLES + 12);
  }

  // ---- interaction -------------------------------------------------------------------

  /** The kept cut whose handle is under the pointer (only in the handle strip, never while dense). */
  private hitCut(x: number, y: number): Cut | null {
    const m = this.model;
    if (!m) return null;
    const cuts = m.cuts.filter(isKept).map((cut) => ({ id: cut.id, x: this.x(cut.frame), cut }));
    const id = hitHandle(this.rows(), cuts, x, y, this.dense, m.selectedCutId);
    return cuts.find((c) => c.id === id)?.cut ?? null;
  }

  /** A deleted candidate's × in the handle strip under the pointer. */
  private hitDeleted(x: number, y: number): Cut | null {
    const m = this.model;
    if (!m) return null;
    const deleted = m.cuts.filter((c) => c.fate === "deleted" && c.origin === "candidate").map((cut) => ({ id: cut.id, x: this.x(cut.frame), cut }));
    const id = hitHandle(this.rows(), deleted, x, y, this.dense, null);
    return deleted.find((c) => c.id === id)?.cut ?? null;
  }

  private point(e: MouseEvent): [number, number] {
    const rect = this.canvas.getBoundingClientRect();
    return [e.clientX - rect.left, e.clientY - rect.top];
  }

  private onDown(e: PointerEvent): void {
    if (!this.model || (e.button !== 0 && e.button !== 1)) return;
    const [x, y] = this.point(e);
    this.canvas.setPointerCapture(e.pointerId);
    const zone = zoneAt(this.rows(), y);
    if (e.button === 1 || e.altKey) {
      e.preventDefault();
      this.gesture = { kind: "pan", lastX: x };
    } else if (zone === "overview") {
      this.gesture = { kind: "overview" };
      this.seekOverview(x);
    } else if (zone === "ruler" && e.shiftKey) {
      const frame = snapFrame(this.view, x);
      this.gesture = { kind: "loop", from: frame, to: frame };
    } else if (!this.grab(x, y)) {
      this.gesture = { kind: "scrub" };
      this.handlers.seek(snapFrame(this.view, x));
    }
  }

  /** A press in the handle strip: on a cut's handle it grabs the cut, on a deleted ×, restores it. */
  private grab(x: number, y: number): boolean {
    const cut = this.hitCut(x, y);
    if (cut) {
      this.gesture = { kind: "drag", cut, startX: x, moved: false, frame: cut.frame };
      return true;
    }
    const deleted = this.hitDeleted(x, y);
    if (!deleted || this.model?.readOnly) return false;
    this.handlers.restoreCut(deleted.id);
    return true;
  }

  private onMove(e: PointerEvent): void {
    const [x, y] = this.point(e);
    const g = this.gesture;
    if (!g) {
      this.canvas.style.cursor = this.hitCut(x, y) ? (this.model?.readOnly ? "pointer" : "ew-resize") : this.hitDeleted(x, y) ? "pointer" : "crosshair";
      this.hoverX = zoneAt(this.rows(), y) === "overview" ? null : x;
      this.hoverY = y;
      this.schedule();
      return;
    }
    if (g.kind === "overview") this.seekOverview(x);
    else if (g.kind === "scrub") this.handlers.seek(snapFrame(this.view, x));
    else if (g.kind === "pan") {
      this.setView(panBy(this.view, x - g.lastX));
      g.lastX = x;
    } else if (g.kind === "loop") {
      g.to = snapFrame(this.view, x);
      this.loopPreview = { start: Math.min(g.from, g.to), stop: Math.max(g.from, g.to) + 1 };
      this.schedule();
    } else if (!this.model?.readOnly && (g.moved || isDrag(g.startX, x))) {
      g.moved = true;
      g.frame = Math.min(Math.max(snapFrame(this.view, x), 1), this.model!.nFrames - 1);
      this.schedule();
    }
  }

  private onUp(e: PointerEvent): void {
    const g = this.gesture;
    this.gesture = null;
    if (this.canvas.hasPointerCapture(e.pointerId)) this.canvas.releasePointerCapture(e.pointerId);
    if (g?.kind === "loop") {
      this.loopPreview = null;
      const [start, stop] = [Math.min(g.from, g.to), Math.max(g.from, g.to) + 1];
      // A shift-click without a drag clears the loop.
      this.handlers.setLoop(stop - start >= 2 ? { start, stop } : null);
      return;
    }
    if (g?.kind !== "drag") return;
    // A click on a handle selects its cut; only a drag past the threshold moves it.
    // Accepting is a command of its own (A, or the Accept button), never a side effect.
    this.handlers.selectCut(g.cut.id);
    if (g.moved && g.frame !== g.cut.frame) this.handlers.moveCut(g.cut.id, g.frame);
    this.schedule();
  }

  /** A double-click in the lanes inserts a cut there; not on the ruler, a handle or the overview. */
  private onDoubleClick(e: MouseEvent): void {
    const [x, y] = this.point(e);
    if (!this.model || this.model.readOnly || zoneAt(this.rows(), y) !== "lanes") return;
    this.handlers.insertAt(snapFrame(this.view, x));
  }

  private onWheel(e: WheelEvent): void {
    e.preventDefault();
    const [x] = this.point(e);
    if (e.shiftKey || Math.abs(e.deltaX) > Math.abs(e.deltaY)) {
      this.setView(panBy(this.view, -(e.deltaX || e.deltaY)));
    } else {
      this.setView(zoomAround(this.view, x, Math.exp(e.deltaY * 0.0015)));
    }
  }

  /** The overview is a ruler for the whole take: seek there, and the working window centres on it. */
  private seekOverview(x: number): void {
    if (!this.model) return;
    const frame = overviewFrame(x, this.width, this.model.nFrames);
    this.setView({ ...this.view, start: frame - this.view.span / 2 });
    this.handlers.seek(frame);
  }
}
