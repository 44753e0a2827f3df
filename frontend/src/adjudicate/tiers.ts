// The adjudication timeline: one ELAN-style tier per submitted review and the gold tier on
// top, all on one time axis (the review page's timescale), with a ruler, the playhead,
// disagreement marks, and gold cuts that drag and snap to the tiers' cuts.

import type { Span } from "../library/types";
import { clampView, frameToX, fullView, resize, snapFrame, ticks, formatTime, zoomAround, type View } from "../review/timescale";
import { clear, h } from "../ui/dom";
import { snapToCuts, type CutMark } from "./marks";

export interface Tier {
  id: string;
  name: string;
  cuts: number[];
  marks: CutMark[];
  segments: Span[];
}

export interface TierModel {
  nFrames: number;
  fps: number;
  colors: Map<string, string>;
  gold: { cuts: number[]; segments: Span[] };
  tiers: Tier[];
  conflicts: { start: number; stop: number }[];
  playhead: number;
  selectedCut: number | null;
}

export interface TierHandlers {
  seek(frame: number): void;
  takeCut(frame: number): void;
  takeSegment(span: Span): void;
  selectGoldCut(index: number): void;
  moveGoldCut(index: number, frame: number): void;
  snapTargets(): number[];
}

/** Pixels within which a dragged gold cut jumps onto a tier's cut. */
const SNAP_PX = 8;

export class Tiers {
  private view: View;
  private model: TierModel | null = null;
  private readonly body: HTMLElement;

  constructor(
    private readonly root: HTMLElement,
    private readonly handlers: TierHandlers,
    nFrames: number,
  ) {
    this.view = fullView(nFrames, 800);
    this.body = h("div", { class: "tiers-body" });
    root.append(this.body);
    root.addEventListener("wheel", (e) => {
      e.preventDefault();
      this.zoom(e.deltaY > 0 ? 1.25 : 0.8, this.frameAtClient(e.clientX));
    }, { passive: false });
  }

  zoom(factor: number, aroundFrame: number): void {
    const x = frameToX(this.view, aroundFrame);
    this.view = zoomAround(this.view, x, factor);
    this.draw();
  }

  update(model: TierModel): void {
    this.model = model;
    this.draw();
  }

  private laneWidth(): number {
    const lane = this.body.querySelector(".tier-lane") as HTMLElement | null;
    return lane?.clientWidth || Math.max(this.root.clientWidth - 140, 200);
  }

  private frameAtClient(clientX: number): number {
    const lane = this.body.querySelector(".tier-lane") as HTMLElement | null;
    const left = lane?.getBoundingClientRect().left ?? 0;
    return snapFrame(this.view, clientX - left);
  }

  private x(frame: number): string {
    return `${frameToX(this.view, frame)}px`;
  }

  private draw(): void {
    const m = this.model;
    if (!m) return;
    this.view = clampView(resize(this.view, this.laneWidth()));
    clear(this.body, this.ruler(m), this.goldRow(m), this.conflictRow(m), ...m.tiers.map((t) => this.tierRow(m, t)));
  }

  private row(name: HTMLElement | string, testid: string, cls: string, ...lane: (HTMLElement | null)[]): HTMLElement {
    const laneEl = h("div", { class: "tier-lane", "data-testid": testid }, ...lane);
    return h("div", { class: `tier ${cls}` }, h("div", { class: "tier-name" }, name), laneEl);
  }

  private ruler(m: TierModel): HTMLElement {
    const marks = ticks(this.view, m.fps).map((f) => h("span", { class: "tick", style: `left:${this.x(f)}` }, formatTime(f, m.fps)));
    const lane = this.row("", "tiers-ruler", "tier-ruler", ...marks, h("div", { class: "tier-playhead", style: `left:${this.x(m.playhead)}`, "data-testid": "tiers-playhead" }));
    lane.querySelector(".tier-lane")!.addEventListener("pointerdown", (e) => this.handlers.seek(this.frameAtClient((e as PointerEvent).clientX)));
    return lane;
  }

  private segments(m: TierModel, spans: Span[], testid: string, onPick: (s: Span, i: number) => void): HTMLElement[] {
    return spans.map((s, i) =>
      h(
        "div",
        {
          class: `tier-seg${s.label ? "" : " unlabelled"}`,
          style: `left:${this.x(s.start)};width:${frameToX(this.view, s.stop) - frameToX(this.view, s.start)}px;background:${s.label ? m.colors.get(s.label) ?? "#888" : "transparent"}`,
          title: `${s.label ?? "unlabelled"} · frames ${s.start}–${s.stop}`,
          "data-testid": `${testid}-seg-${i}`,
          onclick: () => onPick(s, i),
        },
        h("span", {}, s.label ?? ""),
      ),
    );
  }

  private playhead(m: TierModel): HTMLElement {
    return h("div", { class: "tier-playhead", style: `left:${this.x(m.playhead)}` });
  }

  private tierRow(m: TierModel, t: Tier): HTMLElement {
    const testid = `track-${t.name}`;
    const cuts = t.cuts.map((frame, i) =>
      h("div", {
        class: `tier-cut mark-${t.marks[i]}`,
        style: `left:${this.x(frame)}`,
        title: `${t.name}: cut at ${frame} (${t.marks[i]}) — click to take it into gold`,
        "data-testid": `${testid}-cut-${i}`,
        "data-mark": t.marks[i],
        onclick: (e: Event) => {
          e.stopPropagation();
          this.handlers.takeCut(frame);
        },
      }),
    );
    const lane = [...this.segments(m, t.segments, testid, (s) => this.handlers.takeSegment(s)), ...cuts, this.playhead(m)];
    return this.row(h("span", {}, h("b", {}, t.name)), testid, "tier-review", ...lane);
  }

  private conflictRow(m: TierModel): HTMLElement {
    const bands = m.conflicts.map((c, i) =>
      h("div", { class: "tier-conflict", style: `left:${this.x(c.start)};width:${frameToX(this.view, c.stop) - frameToX(this.view, c.start)}px`, title: `labels differ, frames ${c.start}–${c.stop}`, "data-testid": `label-conflict-${i}`, onclick: () => this.handlers.seek(c.start) }),
    );
    return this.row(h("span", { class: "muted small" }, "labels differ"), "tiers-conflicts", "tier-conflicts", ...bands);
  }

  private goldRow(m: TierModel): HTMLElement {
    const cuts = m.gold.cuts.map((frame, i) => {
      const el = h("div", {
        class: `tier-cut gold-cut${m.selectedCut === i ? " selected" : ""}`,
        style: `left:${this.x(frame)}`,
        title: `gold cut at ${frame} — drag to move (snaps to the tiers' cuts); D deletes`,
        "data-testid": `gold-cut-handle-${i}`,
      });
      el.addEventListener("pointerdown", (e) => this.dragGoldCut(e, el, i));
      return el;
    });
    const segs = this.segments(m, m.gold.segments, "track-gold", (s) => this.handlers.seek(s.start));
    return this.row(h("span", {}, h("b", {}, "Gold")), "track-gold", "tier-gold", ...segs, ...cuts, this.playhead(m));
  }

  private dragGoldCut(e: PointerEvent, el: HTMLElement, index: number): void {
    e.preventDefault();
    e.stopPropagation();
    const targets = this.handlers.snapTargets();
    const reach = (SNAP_PX / this.view.width) * this.view.span;
    let frame: number | null = null;
    const move = (ev: PointerEvent) => {
      frame = snapToCuts(this.frameAtClient(ev.clientX), targets, reach);
      el.style.left = this.x(frame);
      el.dataset.frame = String(frame);
    };
    const up = () => {
      document.removeEventListener("pointermove", move);
      document.removeEventListener("pointerup", up);
      // A press without a move selects the cut; a drag moves it (and selects it).
      if (frame === null) this.handlers.selectGoldCut(index);
      else this.handlers.moveGoldCut(index, frame);
    };
    document.addEventListener("pointermove", move);
    document.addEventListener("pointerup", up);
  }
}
