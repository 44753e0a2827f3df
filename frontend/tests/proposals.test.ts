import { describe, expect, it } from "vitest";
import type { Segment } from "../src/api/types";
import { drawProposal, type Scene } from "../src/review/timelinedraw";

/** A canvas context that records what a drawing does. */
function recorder() {
  const calls: { dash: number[][]; texts: { text: string; font: string; fill: unknown }[]; rects: number } = { dash: [], texts: [], rects: 0 };
  const ctx = {
    font: "", fillStyle: "", strokeStyle: "", lineWidth: 1,
    save() {}, restore() {},
    setLineDash(d: number[]) { calls.dash.push(d); },
    strokeRect() { calls.rects++; },
    measureText(t: string) { return { width: t.length * 6 }; },
    fillText(text: string) { calls.texts.push({ text, font: ctx.font, fill: ctx.fillStyle }); },
  };
  return { ctx, calls };
}

const segment = (p: number | null): Segment =>
  ({ index: 2, start: 100, stop: 400, label: null, suggested_label: "walk", proposed_probability: p }) as Segment;

describe("proposed labels in the timeline", () => {
  it("test_it_draws_a_proposal_dashed_in_italics_with_its_probability", () => {
    const { ctx, calls } = recorder();
    drawProposal({ ctx, rows: { segTop: 200 } } as unknown as Scene, segment(0.724), "walk", "#3b82f6", 10, 300);
    expect(calls.rects).toBe(1);
    expect(calls.dash[0].length).toBeGreaterThan(0);
    expect(calls.texts).toEqual([{ text: "walk? 72 %", font: expect.stringContaining("italic"), fill: "#3b82f6" }]);
  });

  it("test_it_draws_a_library_suggestion_without_a_probability", () => {
    const { ctx, calls } = recorder();
    drawProposal({ ctx, rows: { segTop: 200 } } as unknown as Scene, segment(null), "walk", "#3b82f6", 10, 300);
    expect(calls.texts.map((t) => t.text)).toEqual(["walk?"]);
  });

  it("test_it_leaves_out_the_text_where_the_segment_is_too_narrow", () => {
    const { ctx, calls } = recorder();
    drawProposal({ ctx, rows: { segTop: 200 } } as unknown as Scene, segment(0.5), "walk", "#3b82f6", 10, 30);
    expect(calls.rects).toBe(1);
    expect(calls.texts).toEqual([]);
  });
});
