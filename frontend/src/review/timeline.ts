// The timeline: ruler, feature signal lane(s), cut lines, segment bands and an overview
// strip, all drawn on one canvas against one time axis (timescale.ts). No DOM node per
// frame or per cut, so a 72,000-frame take with hundreds of cuts draws in a few ms.

import type { Cut, Label, Segment, Signal } from "../api/types";
import { isKept } from "./state";
import { clampView, follow, formatTime, frameToX, fullView, panBy, resize, snapFrame, ticks, zoomAround, type View } from "./timescale";

export interface TimelineModel {
  nFrames: number;
  fps: number;
  signals: Signal[];
  cuts: Cut[];
  segments: Segment[];
  labels: Label[];
  playhead: number;
  selectedCutId: number | null;
  loop: { start: number; stop: number } | null;
  readOnly: boolean;
}

export interface TimelineHandlers {
  seek(frame: number): void;
  selectCut(id: number | null): void;
  acceptCut(id: number): void;
  moveCut(id: number, frame: number): void;
  insertAt(frame: number): void;
  setLoop(range: { start: number; stop: number } | null): void;
  restoreCut(id: number): void;
}

const RULER = 26;
const LANE = 70;
const SEGMENTS = 30;
const OVERVIEW = 16;
const GAP = 6;
const HIT_PX = 6;
const SIGNAL_COLOURS = ["#7fd3ff", "#b39dff", "#7ee2a8"];

interface Layout {
  lanes: { top: number; height: number }[];
  segTop: number;
  overviewTop: number;
  height: number;
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
  private ranges = new Map<Signal, [number, number]>();
  private gesture: Gesture | null = null;
  private loopPreview: { start: number; stop: number } | null = null;
  private hoverX: number | null = null;
  private hoverY: number | null = null;
  private queued = false;
  private width = 1;
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
    if (this.model?.signals !== model.signals) this.ranges = new Map(model.signals.map((s) => [s, finiteRange(s.values)]));
    this.model = model;
    if (first) {
      this.view = fullView(model.nFrames, this.width);
      this.layoutCanvas();
    }
    this.schedule();
  }

  setView(view: View): void {
    this.view = clampView(view);
    this.onViewChange?.();
    this.schedule();
  }

  zoom(factor: number, aroundFrame?: number): void {
    const x = aroundFrame === undefined ? this.width / 2 : frameToX(this.view, aroundFrame);
    this.setView(zoomAround(this.view, Math.min(Math.max(x, 0), this.width), factor));
  }

  /** Keep the playhead visible while playing or stepping. */
  reveal(frame: number): void {
    const next = follow(this.view, frame);
    if (next !== this.view) this.setView(next);
  }

  private layout(): Layout {
    const n = Math.max(this.model?.signals.length ?? 1, 1);
    const lanes = Array.from({ length: n }, (_, i) => ({ top: RULER + GAP + i * (LANE + GAP), height: LANE }));
    const segTop = RULER + GAP + n * (LANE + GAP);
    const overviewTop = segTop + SEGMENTS + GAP;
    return { lanes, segTop, overviewTop, height: overviewTop + OVERVIEW + 2 };
  }

  private layoutCanvas(): void {
    this.width = Math.max(this.container.clientWidth, 1);
    const height = this.layout().height;
    const dpr = window.devicePixelRatio || 1;
    this.canvas.width = Math.round(this.width * dpr);
    this.canvas.height = Math.round(height * dpr);
    this.canvas.style.width = `${this.width}px`;
    this.canvas.style.height = `${height}px`;
    this.view = clampView(resize(this.view, this.width));
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
    ctx.setTransform(dpr, 0, 0, dpr, 0, 0);
    const L = this.layout();
    ctx.fillStyle = "#12161c";
    ctx.fillRect(0, 0, this.width, L.height);
    this.drawRuler(ctx, m);
    L.lanes.forEach((lane, i) => this.drawSignal(ctx, m.signals[i], lane, SIGNAL_COLOURS[i % SIGNAL_COLOURS.length]));
    this.drawSegments(ctx, m, L.segTop);
    this.drawCuts(ctx, m, RULER, L.segTop + SEGMENTS);
    this.drawHover(ctx, m, L.segTop + SEGMENTS);
    this.drawPlayhead(ctx, m, L.segTop + SEGMENTS);
    this.drawOverview(ctx, m, L.overviewTop);
  }

  private x(frame: number): number {
    return frameToX(this.view, frame);
  }

  private drawRuler(ctx: CanvasRenderingContext2D, m: TimelineModel): void {
    ctx.fillStyle = "#1a1f27";
    ctx.fillRect(0, 0, this.width, RULER);
    const loop = this.loopPreview ?? m.loop;
    if (loop) {
      ctx.fillStyle = "rgba(126, 226, 168, 0.25)";
      ctx.fillRect(this.x(loop.start), 0, this.x(loop.stop) - this.x(loop.start), RULER);
    }
    ctx.font = "11px ui-monospace, SFMono-Regular, Menlo, monospace";
    ctx.textBaseline = "middle";
    for (const frame of ticks(this.view, m.fps, 130)) {
      const x = Math.round(this.x(frame)) + 0.5;
      ctx.strokeStyle = "#3a4350";
      ctx.beginPath();
      ctx.moveTo(x, RULER - 10);
      ctx.lineTo(x, RULER);
      ctx.stroke();
      const time = formatTime(frame, m.fps);
      ctx.fillStyle = "#aab4c3";
      ctx.fillText(time, x + 4, RULER / 2 - 2);
      ctx.fillStyle = "#5f6b7c";
      ctx.fillText(String(frame), x + 10 + ctx.measureText(time).width, RULER / 2 - 2);
    }
  }

  private drawSignal(ctx: CanvasRenderingContext2D, signal: Signal | undefined, lane: { top: number; height: number }, colour: string): void {
    ctx.fillStyle = "#161b22";
    ctx.fillRect(0, lane.top, this.width, lane.height);
    if (!signal || signal.values.length === 0) {
      ctx.fillStyle = "#5c6778";
      ctx.fillText("no feature signal for this capture yet", 10, lane.top + lane.height / 2);
      return;
    }
    const [lo, hi] = this.ranges.get(signal) ?? [0, 1];
    const y = (v: number) => lane.top + 4 + (1 - (v - lo) / (hi - lo || 1)) * (lane.height - 8);
    const step = signal.step || 1;
    const first = Math.max(Math.floor((this.view.start - signal.start) / step) - 1, 0);
    const last = Math.min(Math.ceil((this.view.start + this.view.span - signal.start) / step) + 1, signal.values.length - 1);
    ctx.beginPath();
    if (last - first > this.width * 2) {
      // More samples than pixels: draw each pixel column's min-max, the classic waveform view.
      // Joined column to column, so a smooth curve stays a line and a noisy one a band.
      const columns = columnExtremes(signal, first, last, (i) => this.x(signal.start + i * step), this.width);
      let started = false;
      columns.forEach(([a, b], px) => {
        if (Number.isNaN(a)) return;
        if (started) ctx.lineTo(px + 0.5, y(a));
        else ctx.moveTo(px + 0.5, y(a));
        ctx.lineTo(px + 0.5, y(b) + 0.5);
        started = true;
      });
    } else {
      for (let i = first; i <= last; i++) {
        const v = signal.values[i];
        if (!Number.isFinite(v)) continue;
        if (i === first) ctx.moveTo(this.x(signal.start + i * step), y(v));
        else ctx.lineTo(this.x(signal.start + i * step), y(v));
      }
    }
    ctx.strokeStyle = colour;
    ctx.lineWidth = 1.25;
    ctx.stroke();
    ctx.lineWidth = 1;
    // The lane's name on a backing plate, so the curve never runs through it.
    ctx.font = "11px system-ui, sans-serif";
    const w = ctx.measureText(signal.name).width;
    ctx.fillStyle = "rgba(22, 27, 34, 0.85)";
    ctx.fillRect(4, lane.top + 3, w + 8, 15);
    ctx.fillStyle = "#8792a3";
    ctx.fillText(signal.name, 8, lane.top + 11);
  }

  private drawSegments(ctx: CanvasRenderingContext2D, m: TimelineModel, top: number): void {
    const colours = new Map(m.labels.map((l) => [l.name, l.color]));
    const current = m.segments.find((s) => s.start <= m.playhead && m.playhead < s.stop);
    ctx.font = "600 12px system-ui, sans-serif";
    for (const s of m.segments) {
      const x0 = Math.max(this.x(s.start), -2);
      const x1 = Math.min(this.x(s.stop), this.width + 2);
      if (x1 < 0 || x0 > this.width) continue;
      const colour = s.label ? colours.get(s.label) ?? "#8a93a3" : null;
      ctx.fillStyle = colour ?? "#222933";
      ctx.globalAlpha = colour ? 0.85 : 1;
      ctx.fillRect(x0 + 1, top, Math.max(x1 - x0 - 2, 1), SEGMENTS);
      ctx.globalAlpha = 1;
      if (s === current) {
        ctx.strokeStyle = "#ffffff";
        ctx.lineWidth = 2;
        ctx.strokeRect(x0 + 2, top + 1, Math.max(x1 - x0 - 4, 1), SEGMENTS - 2);
        ctx.lineWidth = 1;
      }
      const text = s.label ?? "unlabelled";
      if (x1 - x0 > ctx.measureText(text).width + 12) {
        ctx.fillStyle = colour ? readableOn(colour) : "#6b7687";
        ctx.fillText(text, Math.max(x0, 0) + 6, top + SEGMENTS / 2);
      }
    }
  }

  private drawCuts(ctx: CanvasRenderingContext2D, m: TimelineModel, top: number, bottom: number): void {
    const drag = this.gesture?.kind === "drag" && this.gesture.moved ? this.gesture : null;
    this.drawDeleted(ctx, m, top);
    for (const cut of m.cuts) {
      if (!isKept(cut)) continue;
      const frame = drag && drag.cut.id === cut.id ? drag.frame : cut.frame;
      const x = Math.round(this.x(frame)) + 0.5;
      if (x < -4 || x > this.width + 4) continue;
      const selected = cut.id === m.selectedCutId;
      if (cut.fate === "moved" && cut.candidate_frame !== null) this.drawGhost(ctx, cut.candidate_frame, x, top);
      const pending = cut.fate === "pending";
      const confidence = cut.confidence ?? 0.6;
      ctx.setLineDash(pending ? [5, 4] : []);
      ctx.globalAlpha = pending ? 0.3 + 0.7 * confidence : 1;
      ctx.strokeStyle = selected ? "#4fc3f7" : pending ? "#ffca28" : "#f5f7fa";
      ctx.lineWidth = selected ? 2.5 : pending ? 1 + confidence : 2;
      ctx.beginPath();
      ctx.moveTo(x, top);
      ctx.lineTo(x, bottom);
      ctx.stroke();
      // A handle in the ruler shows where to grab.
      ctx.setLineDash([]);
      ctx.fillStyle = ctx.strokeStyle;
      ctx.beginPath();
      ctx.moveTo(x - 5, top - 9);
      ctx.lineTo(x + 5, top - 9);
      ctx.lineTo(x, top - 1);
      ctx.fill();
      ctx.globalAlpha = 1;
    }
    ctx.setLineDash([]);
    ctx.lineWidth = 1;
    if (drag) {
      ctx.fillStyle = "#4fc3f7";
      ctx.font = "600 11px ui-monospace, monospace";
      ctx.fillText(`→ ${drag.frame}`, this.x(drag.frame) + 6, top + 12);
    }
  }

  /** Deleted candidates stay findable: a small grey × each, which a click restores. */
  private drawDeleted(ctx: CanvasRenderingContext2D, m: TimelineModel, top: number): void {
    ctx.strokeStyle = "#6b7687";
    ctx.lineWidth = 1.25;
    ctx.beginPath();
    for (const cut of m.cuts) {
      if (cut.fate !== "deleted" || cut.origin !== "candidate") continue;
      const x = Math.round(this.x(cut.frame)) + 0.5;
      if (x < -4 || x > this.width + 4) continue;
      ctx.moveTo(x - 3, top - 8);
      ctx.lineTo(x + 3, top - 2);
      ctx.moveTo(x + 3, top - 8);
      ctx.lineTo(x - 3, top - 2);
    }
    ctx.stroke();
    ctx.lineWidth = 1;
  }

  /** Where a moved cut was proposed: a hollow marker in the ruler joined to the cut. */
  private drawGhost(ctx: CanvasRenderingContext2D, frame: number, cutX: number, top: number): void {
    const x = Math.round(this.x(frame)) + 0.5;
    ctx.setLineDash([2, 3]);
    ctx.strokeStyle = "#7f8a9b";
    ctx.lineWidth = 1;
    ctx.beginPath();
    ctx.moveTo(x - 4, top - 8);
    ctx.lineTo(x + 4, top - 8);
    ctx.lineTo(x, top - 1);
    ctx.closePath();
    ctx.moveTo(x, top - 4);
    ctx.lineTo(cutX, top - 4);
    ctx.stroke();
    ctx.setLineDash([]);
  }

  /** A faint line under the pointer with its frame and time, so a cut can be aimed. */
  private drawHover(ctx: CanvasRenderingContext2D, m: TimelineModel, bottom: number): void {
    if (this.hoverX === null || this.gesture) return;
    const frame = snapFrame(this.view, this.hoverX);
    const x = Math.round(this.x(frame)) + 0.5;
    ctx.strokeStyle = "rgba(255, 255, 255, 0.25)";
    ctx.beginPath();
    ctx.moveTo(x, RULER);
    ctx.lineTo(x, bottom);
    ctx.stroke();
    const deleted = this.hoverY === null ? null : this.hitDeleted(this.hoverX, this.hoverY);
    const text = deleted ? `deleted cut at ${deleted.frame} · click to restore` : `${frame} · ${formatTime(frame, m.fps)}`;
    ctx.font = "11px ui-monospace, SFMono-Regular, Menlo, monospace";
    const w = ctx.measureText(text).width + 8;
    const left = Math.min(Math.max(x + 4, 0), this.width - w);
    ctx.fillStyle = "#2a3340";
    ctx.fillRect(left, RULER + 2, w, 15);
    ctx.fillStyle = "#dfe5ee";
    ctx.fillText(text, left + 4, RULER + 10);
  }

  private drawPlayhead(ctx: CanvasRenderingContext2D, m: TimelineModel, bottom: number): void {
    const x = Math.round(this.x(m.playhead)) + 0.5;
    ctx.strokeStyle = "#ff5a5f";
    ctx.lineWidth = 1.5;
    ctx.beginPath();
    ctx.moveTo(x, 0);
    ctx.lineTo(x, bottom);
    ctx.stroke();
    ctx.fillStyle = "#ff5a5f";
    ctx.fillRect(x - 4, 0, 8, 6);
    ctx.lineWidth = 1;
  }

  private drawOverview(ctx: CanvasRenderingContext2D, m: TimelineModel, top: number): void {
    const whole = fullView(m.nFrames, this.width);
    const colours = new Map(m.labels.map((l) => [l.name, l.color]));
    ctx.fillStyle = "#1a1f27";
    ctx.fillRect(0, top, this.width, OVERVIEW);
    for (const s of m.segments) {
      if (!s.label) continue;
      ctx.fillStyle = colours.get(s.label) ?? "#8a93a3";
      ctx.globalAlpha = 0.6;
      ctx.fillRect(frameToX(whole, s.start), top + 3, frameToX(whole, s.stop) - frameToX(whole, s.start), OVERVIEW - 6);
    }
    ctx.globalAlpha = 1;
    const x0 = frameToX(whole, this.view.start);
    const w = Math.max(frameToX(whole, this.view.start + this.view.span) - x0, 3);
    ctx.strokeStyle = "#9fb3c8";
    ctx.strokeRect(x0 + 0.5, top + 0.5, w - 1, OVERVIEW - 1);
    ctx.fillStyle = "#ff5a5f";
    ctx.fillRect(frameToX(whole, m.playhead) - 0.5, top, 1.5, OVERVIEW);
  }

  // ---- interaction -------------------------------------------------------------------

  private hitCut(x: number, y: number): Cut | null {
    const m = this.model;
    if (!m || y >= this.layout().overviewTop) return null;
    let best: Cut | null = null;
    let bestDistance = HIT_PX + 1;
    for (const cut of m.cuts) {
      if (!isKept(cut)) continue;
      const d = Math.abs(this.x(cut.frame) - x) - (cut.id === m.selectedCutId ? 1 : 0);
      if (d < bestDistance) [best, bestDistance] = [cut, d];
    }
    return bestDistance <= HIT_PX ? best : null;
  }

  /** A deleted candidate's marker (a small × at the foot of the ruler) under the pointer. */
  private hitDeleted(x: number, y: number): Cut | null {
    const m = this.model;
    if (!m || y < RULER - 12 || y > RULER + 2) return null;
    let best: Cut | null = null;
    let bestDistance = HIT_PX + 1;
    for (const cut of m.cuts) {
      if (cut.fate !== "deleted" || cut.origin !== "candidate") continue;
      const d = Math.abs(this.x(cut.frame) - x);
      if (d < bestDistance) [best, bestDistance] = [cut, d];
    }
    return bestDistance <= HIT_PX ? best : null;
  }

  private point(e: MouseEvent): [number, number] {
    const rect = this.canvas.getBoundingClientRect();
    return [e.clientX - rect.left, e.clientY - rect.top];
  }

  private onDown(e: PointerEvent): void {
    if (!this.model || (e.button !== 0 && e.button !== 1)) return;
    const [x, y] = this.point(e);
    this.canvas.setPointerCapture(e.pointerId);
    if (e.button === 1 || e.altKey) {
      e.preventDefault();
      this.gesture = { kind: "pan", lastX: x };
      return;
    }
    if (e.shiftKey && y < RULER) {
      const frame = snapFrame(this.view, x);
      this.gesture = { kind: "loop", from: frame, to: frame };
      return;
    }
    if (y >= this.layout().overviewTop) {
      this.gesture = { kind: "overview" };
      this.centreOverview(x);
      return;
    }
    const cut = this.hitCut(x, y);
    if (cut) {
      this.gesture = { kind: "drag", cut, startX: x, moved: false, frame: cut.frame };
      return;
    }
    const deleted = this.hitDeleted(x, y);
    if (deleted && !this.model.readOnly) {
      this.handlers.restoreCut(deleted.id);
      return;
    }
    this.gesture = { kind: "scrub" };
    this.handlers.seek(snapFrame(this.view, x));
  }

  private onMove(e: PointerEvent): void {
    const [x, y] = this.point(e);
    const g = this.gesture;
    if (!g) {
      this.canvas.style.cursor = this.hitCut(x, y) ? (this.model?.readOnly ? "pointer" : "ew-resize") : this.hitDeleted(x, y) ? "pointer" : "crosshair";
      this.hoverX = y < this.layout().overviewTop ? x : null;
      this.hoverY = y;
      this.schedule();
      return;
    }
    if (g.kind === "overview") this.centreOverview(x);
    else if (g.kind === "scrub") this.handlers.seek(snapFrame(this.view, x));
    else if (g.kind === "pan") {
      this.setView(panBy(this.view, x - g.lastX));
      g.lastX = x;
    } else if (g.kind === "loop") {
      g.to = snapFrame(this.view, x);
      this.loopPreview = { start: Math.min(g.from, g.to), stop: Math.max(g.from, g.to) + 1 };
      this.schedule();
    }
    else if (!this.model?.readOnly && (g.moved || Math.abs(x - g.startX) > 3)) {
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
    this.handlers.selectCut(g.cut.id);
    if (g.moved && g.frame !== g.cut.frame) this.handlers.moveCut(g.cut.id, g.frame);
    else if (!g.moved && g.cut.fate === "pending" && !this.model?.readOnly) this.handlers.acceptCut(g.cut.id);
    this.schedule();
  }

  private onDoubleClick(e: MouseEvent): void {
    const [x, y] = this.point(e);
    if (!this.model || this.model.readOnly || y >= this.layout().overviewTop || this.hitCut(x, y)) return;
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

  private centreOverview(x: number): void {
    if (!this.model) return;
    const frame = (x / this.width) * this.model.nFrames;
    this.setView({ ...this.view, start: frame - this.view.span / 2 });
  }
}

/** Finite min and max of a signal (NaN gaps allowed), widened when flat. */
export function finiteRange(values: readonly number[]): [number, number] {
  let lo = Infinity;
  let hi = -Infinity;
  for (const v of values) {
    if (!Number.isFinite(v)) continue;
    if (v < lo) lo = v;
    if (v > hi) hi = v;
  }
  if (lo === Infinity) return [0, 1];
  return hi > lo ? [lo, hi] : [lo - 0.5, hi + 0.5];
}

/** Per pixel column, the min and max of the samples that land in it (NaN where none do). */
export function columnExtremes(signal: Signal, first: number, last: number, xOf: (i: number) => number, width: number): [number, number][] {
  const columns: [number, number][] = Array.from({ length: Math.ceil(width) }, () => [NaN, NaN]);
  for (let i = first; i <= last; i++) {
    const px = Math.floor(xOf(i));
    const v = signal.values[i];
    if (px < 0 || px >= columns.length || !Number.isFinite(v)) continue;
    const c = columns[px];
    if (Number.isNaN(c[0]) || v < c[0]) c[0] = v;
    if (Number.isNaN(c[1]) || v > c[1]) c[1] = v;
  }
  return columns;
}

/** Black or white text, whichever reads better on `hex`. */
export function readableOn(hex: string): string {
  const n = parseInt(hex.replace("#", "").slice(0, 6), 16);
  const [r, g, b] = [(n >> 16) & 255, (n >> 8) & 255, n & 255];
  return 0.299 * r + 0.587 * g + 0.114 * b > 150 ? "#111418" : "#ffffff";
}
