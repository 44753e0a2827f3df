import { describe, expect, it } from "vitest";
import { addCut, fromSpans, moveCut, removeCut, segmentAt, setLabel, toSpans } from "../src/library/gold";
import { libraryFiltersFrom, libraryQuery, segmentCount } from "../src/library/page";
import { previewStep } from "../src/library/preview";

const spans = [
  { start: 0, stop: 100, label: "walk" },
  { start: 100, stop: 250, label: "punch" },
  { start: 250, stop: 400, label: null },
];

describe("gold draft", () => {
  it("round-trips an annotator's segments", () => {
    const draft = fromSpans(spans);
    expect(draft).toEqual({ cuts: [100, 250], labels: ["walk", "punch", null] });
    expect(toSpans(draft, 400)).toEqual(spans);
  });

  it("splits the segment under a frame, both halves keeping its label", () => {
    const draft = addCut(fromSpans(spans), 180, 400);
    expect(draft).toEqual({ cuts: [100, 180, 250], labels: ["walk", "punch", "punch", null] });
  });

  it("ignores a split on an existing cut or at the ends", () => {
    const draft = fromSpans(spans);
    expect(addCut(draft, 100, 400)).toBe(draft);
    expect(addCut(draft, 0, 400)).toBe(draft);
    expect(addCut(draft, 400, 400)).toBe(draft);
  });

  it("merges two segments when a cut is removed, keeping the earlier label", () => {
    expect(removeCut(fromSpans(spans), 0)).toEqual({ cuts: [250], labels: ["walk", null] });
  });

  it("moves a cut but never past its neighbours", () => {
    const draft = fromSpans(spans);
    expect(moveCut(draft, 0, 120, 400).cuts).toEqual([120, 250]);
    expect(moveCut(draft, 0, 300, 400).cuts).toEqual([249, 250]);
    expect(moveCut(draft, 1, 9999, 400).cuts).toEqual([100, 399]);
  });

  it("finds the segment of a frame and relabels it", () => {
    const draft = fromSpans(spans);
    expect([segmentAt(draft, 0), segmentAt(draft, 99), segmentAt(draft, 100), segmentAt(draft, 399)]).toEqual([0, 0, 1, 2]);
    expect(setLabel(draft, 2, "walk").labels).toEqual(["walk", "punch", "walk"]);
  });
});

describe("library filters", () => {
  it("reads filters from the address and writes back only the set ones", () => {
    const f = libraryFiltersFrom("?label=squat&min_duration=1.5&page=3");
    expect(f.label).toBe("squat");
    expect(f.page).toBe(3);
    expect(libraryQuery(f)).toBe("label=squat&min_duration=1.5&page=3");
    expect(libraryQuery(f, false)).toBe("label=squat&min_duration=1.5");
  });

  it("thins long clips for preview", () => {
    expect(previewStep(1000)).toBe(1);
    expect(previewStep(4500)).toBe(3);
  });
});

describe("suggested labels on the review page", () => {
  it("accepts the suggestion with S", async () => {
    const { commandFor, HELP } = await import("../src/review/keymap");
    const key = { shiftKey: false, ctrlKey: false, metaKey: false, altKey: false };
    expect(commandFor({ ...key, key: "s" })).toEqual({ kind: "acceptSuggestion" });
    expect(commandFor({ ...key, key: "S", shiftKey: true })).toEqual({ kind: "acceptSuggestion" });
    expect(HELP.some(([k]) => k === "S")).toBe(true);
  });
});

describe("opening a capture at a segment", () => {
  it("reads ?frame= and keeps it inside the take", async () => {
    const { frameFromUrl } = await import("../src/review/page");
    expect(frameFromUrl(1000, "?frame=250")).toBe(250);
    expect(frameFromUrl(1000, "?frame=5000")).toBe(999);
    expect(frameFromUrl(1000, "?frame=-3")).toBe(0);
    expect(frameFromUrl(1000, "?frame=abc")).toBe(0);
    expect(frameFromUrl(1000, "")).toBe(0);
  });
});

describe("segment count", () => {
  it("says when the server capped the count", () => {
    expect(segmentCount(1, false)).toBe("1 segment");
    expect(segmentCount(7, false)).toBe("7 segments");
    expect(segmentCount(10000, true)).toBe("10,000+ segments");
  });
});
