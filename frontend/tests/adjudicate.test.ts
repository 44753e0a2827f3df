import { describe, expect, it } from "vitest";
import { back, cutMarks, forward, labelConflicts, push, snapToCuts, start, unlabelledGold } from "../src/adjudicate/marks";
import { filterLabels } from "../src/review/palette";

describe("cutMarks", () => {
  it("marks cuts every tier made within the tolerance as agreed", () => {
    expect(cutMarks([[100, 200], [102, 199]], 5)).toEqual([["agreed", "agreed"], ["agreed", "agreed"]]);
  });

  it("marks matching cuts further apart than the tolerance as shifted", () => {
    expect(cutMarks([[100], [110]], 5)).toEqual([["shifted"], ["shifted"]]);
  });

  it("marks a cut only some annotators made as lone", () => {
    expect(cutMarks([[100, 300], [100]], 5)).toEqual([["agreed", "lone"], ["agreed"]]);
  });

  it("calls a cut lone when one of three tiers lacks it", () => {
    expect(cutMarks([[100], [101], []], 5)[0]).toEqual(["lone"]);
  });
});

describe("labelConflicts", () => {
  it("returns the ranges where labels differ, merged", () => {
    const a = [{ start: 0, stop: 50, label: "walk" }, { start: 50, stop: 100, label: "punch" }];
    const b = [{ start: 0, stop: 60, label: "walk" }, { start: 60, stop: 100, label: "kick" }];
    expect(labelConflicts([a, b], 100)).toEqual([{ start: 50, stop: 100 }]);
  });

  it("finds nothing with one tier", () => {
    expect(labelConflicts([[{ start: 0, stop: 10, label: "walk" }]], 10)).toEqual([]);
  });
});

describe("snapToCuts", () => {
  it("snaps to the nearest cut within reach and keeps the frame otherwise", () => {
    expect(snapToCuts(103, [100, 110], 4)).toBe(100);
    expect(snapToCuts(150, [100, 110], 4)).toBe(150);
  });
});

describe("undo history of gold drafts", () => {
  it("undoes and redoes, and a new edit drops the redo branch", () => {
    let h = push(push(start(1), 2), 3);
    h = back(back(h));
    expect(h.present).toBe(1);
    h = forward(h);
    expect(h.present).toBe(2);
    h = push(h, 9);
    expect(h.future).toEqual([]);
    expect(back(start(1)).present).toBe(1);
  });
});

describe("the label palette filter", () => {
  const labels = ["walk", "crawl", "cartwheel", "kick"].map((name, id) => ({ id, name, color: "#000000", hotkey: null, retired: false }));
  it("lists names starting with the text first, then names containing it", () => {
    expect(filterLabels(labels, "c").map((l) => l.name)).toEqual(["crawl", "cartwheel", "kick"]);
    expect(filterLabels(labels, "WAL").map((l) => l.name)).toEqual(["walk"]);
  });
});

describe("unlabelledGold", () => {
  const draft = { cuts: [100, 200, 300], labels: ["walk", null, "run", null] };
  it("finds the next and the previous gold segment without a label", () => {
    expect(unlabelledGold(draft, 0, 1)).toBe(100);
    expect(unlabelledGold(draft, 100, 1)).toBe(300);
    expect(unlabelledGold(draft, 250, -1)).toBe(100);
    expect(unlabelledGold(draft, 100, -1)).toBeNull();
    expect(unlabelledGold(draft, 300, 1)).toBeNull();
  });
});
