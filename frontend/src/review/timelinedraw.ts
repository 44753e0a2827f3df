// Drawing the timeline's still parts: ruler, cut handles, signal lanes, segment bands, cut
// lines and the overview strip. Drawn once per view and edit into an offscreen canvas
// (timeline.ts), never per played frame, so playing an hour costs what playing a minute does.

import type { Cut, Label, Segment, Signal } from "../api/types";
import { density, HANDLE_HALF, HANDLES, OVERVIEW, RULER, SEGMENTS, overviewX, type Rows } from "./hits";
import { MinMaxPyramid, robustRange, type LaneRange } from "./lanes";
import { isKept } from "./state";
import { formatTime, frameToX, ticks, type View } from "./timescale";

export interface SceneModel {
  nFrames: number;
  fps: number;
  signals: Signal[];
  cuts: Cut[];
  segments: Segment[];
  labels: Label[];
  playhead: number;
  selectedCutId: number | null;
  loop: { start: number; stop: number } | null;
}

/** A signal prepared for drawing: its robust range and its min-max pyramid. */
export interface Lane {
  range: LaneRange;
  pyramid: MinMaxPyramid;
}

export function prepareLane(signal: Signal): Lane {
  return { range: robustRange(signal.values), pyramid: new MinMaxPyramid(signal.values) };
}

export interface Scene {
  ctx: CanvasRenderingContext2D;
  width: number;
  view: View;
  rows: Rows;
  model: SceneModel;
  lanes: Map<Signal, Lane>;
  /** Too many cuts in view to draw one by one: ticks instead of handles and lines. */
  dense: boolean;
  /** A cut being dragged, drawn at `frame`. */
  drag: { id: number; frame: number } | null;
}

const SIGNAL_COLOURS = ["#7fd3ff", "#b39dff", "#7ee2a8"];
const PENDING = "#ffca28";
const SELECTED = "#4fc3f7";
const KEPT = "#f5f7fa";
const MONO = "11px ui-monospace, SFMono-Regular, Menlo, monospace";

export function drawScene(s: Scene): void {
  const { ctx, width, rows } = s;
  ctx.fillStyle = "#12161c";
  ctx.fillRect(0, 0, width, rows.height);
  drawRuler(s);
  rows.lanes.forEach((lane, i) => drawSignal(s, s.model.signals[i], lane, SIGNAL_COLOURS[i % SIGNAL_COLOURS.length]));
  drawSegments(s);
  if (s.dense) drawDenseCuts(s);
  else drawCuts(s);
  drawOverview(s);
}

function x(s: Scene, frame: number): number {
  return frameToX(s.view, frame);
}

function drawRuler(s: Scene): void {
  const { ctx, model: m } = s;
  ctx.fillStyle = "#1a1f27";
  ctx.fillRect(0, 0, s.width, RULER);
  ctx.fillStyle = "#161b22";
  ctx.fillRect(0, RULER, s.width, HANDLES);
  if (m.loop) {
    ctx.fillStyle = "rgba(126, 226, 168, 0.25)";
    ctx.fillRect(x(s, m.loop.start), 0, x(s, m.loop.stop) - x(s, m.loop.start), RULER);
  }
  ctx.font = MONO;
  ctx.textBaseline = "middle";
  ctx.strokeStyle = "#3a4350";
  ctx.beginPath();
  for (const frame of ticks(s.view, m.fps, 130)) {
    const px = Math.round(x(s, frame)) + 0.5;
    ctx.moveTo(px, RULER - 9);
    ctx.lineTo(px, RULER);
  }
  ctx.stroke();
  for (const frame of ticks(s.view, m.fps, 130)) {
    const px = Math.round(x(s, frame)) + 0.5;
    const time = formatTime(frame, m.fps);
    ctx.fillStyle = "#aab4c3";
    ctx.fillText(time, px + 4, RULER / 2 - 1);
    ctx.fillStyle = "#5f6b7c";
    ctx.fillText(String(frame), px + 10 + ctx.measureText(time).width, RULER / 2 - 1);
  }
}

function drawSignal(s: Scene, signal: Signal | undefined, lane: { top: number; height: number }, colour: string): void {
  const { ctx } = s;
  ctx.fillStyle = "#161b22";
  ctx.fillRect(0, lane.top, s.width, lane.height);
  const prepared = signal ? s.lanes.get(signal) : undefined;
  if (!signal || !prepared || signal.values.length === 0) {
    ctx.fillStyle = "#5c6778";
    ctx.fillText("no feature signal for this capture yet", 10, lane.top + lane.height / 2);
    return;
  }
  const { lo, hi } = prepared.range;
  const top = lane.top + 4;
  const h = lane.height - 8;
  const y = (v: number) => top + (1 - (Math.min(Math.max(v, lo), hi) - lo) / (hi - lo)) * h;
  const clipped: number[] = [];
  ctx.beginPath();
  const step = signal.step || 1;
  const perPx = s.view.span / s.width / step;
  if (perPx >= 2) traceColumns(s, prepared.pyramid, (s.view.start - signal.start) / step, perPx, y, hi, lo, clipped);
  else traceSamples(s, signal, y, hi, lo, clipped);
  ctx.strokeStyle = colour;
  ctx.lineWidth = 1.25;
  ctx.stroke();
  ctx.lineWidth = 1;
  drawClipMarks(s, clipped, lane);
  drawLaneName(s, signal.name + (prepared.range.clippedHigh || prepared.range.clippedLow ? " · spikes clipped" : ""), lane);
}

/**
 * More samples than pixels: each pixel column's min-max, the classic waveform view, joined
 * column to column so a smooth curve stays a line and a noisy one a band.
 */
function traceColumns(s: Scene, pyramid: MinMaxPyramid, first: number, perPx: number, y: (v: number) => number, hi: number, lo: number, clipped: number[]): void {
  const { min, max } = pyramid.columns(first, perPx, s.width);
  let started = false;
  for (let px = 0; px < min.length; px++) {
    if (Number.isNaN(min[px])) continue;
    if (started) s.ctx.lineTo(px + 0.5, y(min[px]));
    else s.ctx.moveTo(px + 0.5, y(min[px]));
    s.ctx.lineTo(px + 0.5, y(max[px]) + 0.5);
    started = true;
    if (max[px] > hi) clipped.push(px, 1);
    if (min[px] < lo) clipped.push(px, -1);
  }
}

function traceSamples(s: Scene, signal: Signal, y: (v: number) => number, hi: number, lo: number, clipped: number[]): void {
  const step = signal.step || 1;
  const first = Math.max(Math.floor((s.view.start - signal.start) / step) - 1, 0);
  const last = Math.min(Math.ceil((s.view.start + s.view.span - signal.start) / step) + 1, signal.values.length - 1);
  let started = false;
  for (let i = first; i <= last; i++) {
    const v = signal.values[i];
    if (!Number.isFinite(v)) continue;
    const px = x(s, signal.start + i * step);
    if (started) s.ctx.lineTo(px, y(v));
    else s.ctx.moveTo(px, y(v));
    started = true;
    if (v > hi) clipped.push(px, 1);
    if (v < lo) clipped.push(px, -1);
  }
}

/** Where a value was clipped to the lane's range: a red notch at the lane's edge. */
function drawClipMarks(s: Scene, clipped: number[], lane: { top: number; height: number }): void {
  if (!clipped.length) return;
  const { ctx } = s;
  ctx.fillStyle = "#ff7a59";
  for (let i = 0; i < clipped.length; i += 2) {
    const px = clipped[i];
    const edge = clipped[i + 1] > 0 ? lane.top : lane.top + lane.height - 3;
    ctx.fillRect(px - 1.5, edge, 3, 3);
  }
}

/** The lane's name on a backing plate, so the curve never runs through it. */
function drawLaneName(s: Scene, name: string, lane: { top: number; height: number }): void {
  const { ctx } = s;
  ctx.font = "11px system-ui, sans-serif";
  const w = ctx.measureText(name).width;
  ctx.fillStyle = "rgba(22, 27, 34, 0.85)";
  ctx.fillRect(4, lane.top + 3, w + 8, 15);
  ctx.fillStyle = "#8792a3";
  ctx.fillText(name, 8, lane.top + 11);
}

function drawSegments(s: Scene): void {
  const { ctx, model: m } = s;
  const top = s.rows.segTop;
  const colours = new Map(m.labels.map((l) => [l.name, l.color]));
  ctx.font = "600 12px system-ui, sans-serif";
  for (const seg of m.segments) {
    const x0 = Math.max(x(s, seg.start), -2);
    const x1 = Math.min(x(s, seg.stop), s.width + 2);
    if (x1 < 0 || x0 > s.width) continue;
    const colour = seg.label ? colours.get(seg.label) ?? "#8a93a3" : null;
    ctx.fillStyle = colour ?? "#222933";
    ctx.globalAlpha = colour ? 0.85 : 1;
    ctx.fillRect(x0 + 1, top, Math.max(x1 - x0 - 2, 1), SEGMENTS);
    ctx.globalAlpha = 1;
    if (!seg.label && seg.suggested_label) {
      drawProposal(s, seg, seg.suggested_label, colours.get(seg.suggested_label) ?? "#8a93a3", x0, x1);
      ctx.font = "600 12px system-ui, sans-serif";
      continue;
    }
    const text = seg.label ?? "unlabelled";
    if (x1 - x0 > ctx.measureText(text).width + 12) {
      ctx.fillStyle = colour ? readableOn(colour) : "#6b7687";
      ctx.fillText(text, Math.max(x0, 0) + 6, top + SEGMENTS / 2);
    }
  }
}

/** An unlabelled segment's proposed label, not confirmed: a dashed outline in the label's
 * colour and its name in italics with the proposal's probability, so that it never looks
 * like a label the annotator gave. */
export function drawProposal(s: Scene, seg: Segment, label: string, colour: string, x0: number, x1: number): void {
  const { ctx } = s;
  const top = s.rows.segTop;
  ctx.save();
  ctx.strokeStyle = colour;
  ctx.lineWidth = 1.5;
  ctx.setLineDash([5, 3]);
  ctx.strokeRect(x0 + 1.75, top + 0.75, Math.max(x1 - x0 - 3.5, 1), SEGMENTS - 1.5);
  ctx.restore();
  ctx.font = "italic 12px system-ui, sans-serif";
  const p = seg.proposed_probability;
  const text = p === null || p === undefined ? `${label}?` : `${label}? ${Math.round(p * 100)} %`;
  if (x1 - x0 > ctx.measureText(text).width + 12) {
    ctx.fillStyle = colour;
    ctx.fillText(text, Math.max(x0, 0) + 6, top + SEGMENTS / 2);
  }
}

/** Kept cuts of `m` in view, at their drawn frame (a dragged cut where it is being dragged). */
export function cutsInView(s: Pick<Scene, "view" | "width" | "model" | "drag">): { cut: Cut; frame: number; x: number }[] {
  const out: { cut: Cut; frame: number; x: number }[] = [];
  for (const cut of s.model.cuts) {
    if (!isKept(cut)) continue;
    const frame = s.drag && s.drag.id === cut.id ? s.drag.frame : cut.frame;
    const px = frameToX(s.view, frame);
    if (px >= -HANDLE_HALF && px <= s.width + HANDLE_HALF) out.push({ cut, frame, x: px });
  }
  return out;
}

function cutStyle(s: Scene, cut: Cut): { colour: string; alpha: number; width: number; dash: number[] } {
  const pending = cut.fate === "pending";
  const confidence = cut.confidence ?? 0.6;
  const selected = cut.id === s.model.selectedCutId;
  return {
    colour: selected ? SELECTED : pending ? PENDING : KEPT,
    alpha: pending ? 0.3 + 0.7 * confidence : 1,
    width: selected ? 2.5 : pending ? 1 + confidence : 2,
    dash: pending ? [5, 4] : [],
  };
}

/** Each kept cut: a line through the lanes and a handle in the handle strip, where it is grabbed. */
function drawCuts(s: Scene): void {
  const { ctx, rows } = s;
  drawDeleted(s);
  const lineTop = rows.handlesTop + HANDLES;
  const bottom = rows.segTop + SEGMENTS;
  for (const { cut, x: cx } of cutsInView(s)) {
    const px = Math.round(cx) + 0.5;
    if (cut.fate === "moved" && cut.candidate_frame !== null) drawGhost(s, cut.candidate_frame, px);
    const style = cutStyle(s, cut);
    ctx.setLineDash(style.dash);
    ctx.globalAlpha = style.alpha;
    ctx.strokeStyle = style.colour;
    ctx.lineWidth = style.width;
    ctx.beginPath();
    ctx.moveTo(px, lineTop);
    ctx.lineTo(px, bottom);
    ctx.stroke();
    ctx.setLineDash([]);
    ctx.fillStyle = style.colour;
    ctx.beginPath();
    ctx.moveTo(px - HANDLE_HALF + 1, rows.handlesTop + 2);
    ctx.lineTo(px + HANDLE_HALF - 1, rows.handlesTop + 2);
    ctx.lineTo(px + HANDLE_HALF - 1, rows.handlesTop + 8);
    ctx.lineTo(px, lineTop - 1);
    ctx.lineTo(px - HANDLE_HALF + 1, rows.handlesTop + 8);
    ctx.fill();
    ctx.globalAlpha = 1;
  }
  ctx.setLineDash([]);
  ctx.lineWidth = 1;
}

/**
 * Too many cuts for the pixels (an hour at "Fit"): a tick each in the handle strip and a
 * note to zoom in, instead of a wall of lines; nothing here can be grabbed.
 */
function drawDenseCuts(s: Scene): void {
  const { ctx, rows } = s;
  const cuts = cutsInView(s);
  for (const { cut, x: cx } of cuts) {
    const style = cutStyle(s, cut);
    ctx.globalAlpha = style.alpha;
    ctx.fillStyle = style.colour;
    ctx.fillRect(Math.round(cx), rows.handlesTop + 3, 1, HANDLES - 6);
  }
  ctx.globalAlpha = 1;
  const note = `${cuts.length} cuts in view · zoom in to grab one`;
  ctx.font = "11px system-ui, sans-serif";
  const w = ctx.measureText(note).width + 10;
  ctx.fillStyle = "rgba(22, 27, 34, 0.9)";
  ctx.fillRect(s.width - w - 4, rows.handlesTop + 1, w, HANDLES - 2);
  ctx.fillStyle = "#8792a3";
  ctx.fillText(note, s.width - w + 1, rows.handlesTop + HANDLES / 2);
}

/** Deleted candidates stay findable: a small grey × each in the handle strip, which a click restores. */
function drawDeleted(s: Scene): void {
  const { ctx, rows } = s;
  const mid = rows.handlesTop + HANDLES / 2;
  ctx.strokeStyle = "#6b7687";
  ctx.lineWidth = 1.25;
  ctx.beginPath();
  for (const cut of s.model.cuts) {
    if (cut.fate !== "deleted" || cut.origin !== "candidate") continue;
    const px = Math.round(x(s, cut.frame)) + 0.5;
    if (px < -4 || px > s.width + 4) continue;
    ctx.moveTo(px - 3, mid - 3);
    ctx.lineTo(px + 3, mid + 3);
    ctx.moveTo(px + 3, mid - 3);
    ctx.lineTo(px - 3, mid + 3);
  }
  ctx.stroke();
  ctx.lineWidth = 1;
}

/** Where a moved cut was proposed: a hollow marker in the handle strip joined to the cut. */
function drawGhost(s: Scene, frame: number, cutX: number): void {
  const { ctx, rows } = s;
  const px = Math.round(x(s, frame)) + 0.5;
  const top = rows.handlesTop;
  ctx.setLineDash([2, 3]);
  ctx.strokeStyle = "#7f8a9b";
  ctx.lineWidth = 1;
  ctx.beginPath();
  ctx.moveTo(px - 4, top + 3);
  ctx.lineTo(px + 4, top + 3);
  ctx.lineTo(px, top + HANDLES - 2);
  ctx.closePath();
  ctx.moveTo(px, top + HANDLES / 2);
  ctx.lineTo(cutX, top + HANDLES / 2);
  ctx.stroke();
  ctx.setLineDash([]);
}

/**
 * The whole take in a strip: labelled segments as bands, pending candidates as a density
 * of amber ticks (taller where they crowd), kept cuts as white ticks. The working window
 * and the playhead are drawn over it per frame (timeline.ts).
 */
function drawOverview(s: Scene): void {
  const { ctx, model: m, width } = s;
  const top = s.rows.overviewTop;
  ctx.fillStyle = "#1a1f27";
  ctx.fillRect(0, top, width, OVERVIEW);
  const colours = new Map(m.labels.map((l) => [l.name, l.color]));
  ctx.globalAlpha = 0.55;
  for (const seg of m.segments) {
    if (!seg.label) continue;
    ctx.fillStyle = colours.get(seg.label) ?? "#8a93a3";
    const x0 = overviewX(seg.start, width, m.nFrames);
    ctx.fillRect(x0, top + 8, overviewX(seg.stop, width, m.nFrames) - x0, OVERVIEW - 10);
  }
  ctx.globalAlpha = 1;
  const pending = m.cuts.filter((c) => c.fate === "pending").map((c) => c.frame);
  const kept = m.cuts.filter((c) => isKept(c) && c.fate !== "pending").map((c) => c.frame);
  drawDensity(ctx, density(pending, width, m.nFrames), top + 1, 7, PENDING);
  drawDensity(ctx, density(kept, width, m.nFrames), top + OVERVIEW - 8, 7, KEPT);
}

function drawDensity(ctx: CanvasRenderingContext2D, counts: Uint16Array, top: number, height: number, colour: string): void {
  ctx.fillStyle = colour;
  for (let c = 0; c < counts.length; c++) {
    if (!counts[c]) continue;
    const h = Math.min(2 + counts[c] * 2, height);
    ctx.fillRect(c, top + height - h, 1, h);
  }
}

/** Black or white text, whichever reads better on `hex`. */
export function readableOn(hex: string): string {
  const n = parseInt(hex.replace("#", "").slice(0, 6), 16);
  const [r, g, b] = [(n >> 16) & 255, (n >> 8) & 255, n & 255];
  return 0.299 * r + 0.587 * g + 0.114 * b > 150 ? "#111418" : "#ffffff";
}
