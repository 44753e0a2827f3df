import { describe, expect, it } from "vitest";
import type { ReviewEvent } from "../src/api/types";
import { editTitle, emptyHistory, historyFromEvents, record, stepped } from "../src/review/history";
import { applyEdit, editRequest } from "../src/review/state";
import { review } from "./fixtures";

const N = 1000;
let nextId = 1;

function event(action: string, before: object | null = null, after: object | null = null): ReviewEvent {
  return { id: nextId++, user: "ann", action, cut: 1, before, after, created_at: "2026-01-01T10:00:00Z" } as ReviewEvent;
}

const move = (from: number, to: number) => event("move", { frame: from, fate: "pending" }, { frame: to, fate: "moved" });
const restore = (intent: "undo" | "redo" | null) => event("restore", { cuts: [] }, { event: 1, intent, cuts: [[1, 200, "pending"]], labels: [] });

describe("historyFromEvents", () => {
  it("test_it_makes_every_edit_a_step_and_skips_what_is_not_one", () => {
    const h = historyFromEvents([event("create", null, { candidates: 3 }), move(200, 230), event("submit"), event("return"), move(230, 240)]);
    expect(h).toEqual({ past: ["move frame 200 → 230", "move frame 230 → 240"], future: [] });
  });

  it("test_it_reads_undo_and_redo_restores_as_moves_between_the_stacks", () => {
    const h = historyFromEvents([event("create"), move(200, 230), move(230, 240), restore("undo"), restore("undo"), restore("redo")]);
    expect(h).toEqual({ past: ["move frame 200 → 230"], future: ["move frame 230 → 240"] });
  });

  it("test_it_forgets_the_redo_stack_at_a_new_edit_and_counts_a_plain_restore_as_a_step", () => {
    const h = historyFromEvents([event("create"), move(200, 230), restore("undo"), restore(null)]);
    expect(h).toEqual({ past: ["restore 1 change"], future: [] });
  });

  it("test_it_counts_an_imported_file_as_one_step_named_by_its_file", () => {
    const imported = event("import", { cuts: [], labels: [] }, { cuts: [[1, 200, "accepted"]], labels: [], file: "take.eaf", source: "moves", segments: 3 });
    const h = historyFromEvents([event("create"), move(200, 230), imported, restore("undo")]);
    expect(h).toEqual({ past: ["move frame 200 → 230"], future: ["import 3 segments from take.eaf (moves)"] });
  });

  it("test_it_ignores_an_undo_with_nothing_to_undo", () => {
    expect(historyFromEvents([event("create"), restore("undo")])).toEqual(emptyHistory());
  });
});

describe("stepped", () => {
  it("test_it_moves_the_top_step_across_and_names_it", () => {
    const h = record(record(emptyHistory(), "a"), "b");
    const undone = stepped(h, "undo")!;
    expect(undone).toEqual({ history: { past: ["a"], future: ["b"] }, title: "b" });
    expect(stepped(undone.history, "redo")).toEqual({ history: { past: ["a", "b"], future: [] }, title: "b" });
    expect(stepped(emptyHistory(), "undo")).toBeNull();
  });

  it("test_it_keeps_at_most_the_history_limit", () => {
    let h = emptyHistory();
    for (let i = 0; i < 12; i++) h = record(h, `step ${i}`, 10);
    expect(h.past).toHaveLength(10);
    expect(h.past[0]).toBe("step 2");
  });
});

describe("editTitle and the server's edits", () => {
  it("test_it_titles_each_step_for_the_user", () => {
    const r = review();
    expect(editTitle(r, { kind: "move", cutId: 1, frame: 230 })).toBe("move cut 200 → 230");
    expect(editTitle(r, { kind: "fate", cutId: 1, fate: "accepted" })).toBe("accept cut at 200");
    expect(editTitle(r, { kind: "label", start: 0, stop: 200, label: null })).toBe("clear label");
    const deleted = applyEdit(r, { kind: "fate", cutId: 2, fate: "deleted" }, N);
    expect(editTitle(deleted, { kind: "fate", cutId: 2, fate: "pending" })).toBe("restore cut at 500");
  });

  it("test_it_asks_the_server_for_undo_redo_and_restore_and_predicts_nothing", () => {
    const r = review();
    expect(applyEdit(r, { kind: "undo" }, N)).toBe(r);
    expect(editRequest(3, { kind: "undo" }, 9, (id) => id)).toEqual({ method: "POST", url: "/api/captures/3/review/undo/", body: { version: 9 } });
    expect(editRequest(3, { kind: "restore", event: 41 }, 9, (id) => id, 7)).toEqual({
      method: "POST", url: "/api/captures/3/reviews/7/restore/", body: { event: 41, version: 9 },
    });
  });
});
