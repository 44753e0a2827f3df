import { describe, expect, it } from "vitest";
import type { Review } from "../src/api/types";
import { changeFor, emptyHistory, record, redo, transitionEdits, undo, type History } from "../src/review/history";
import { applyEdit, type Edit } from "../src/review/state";
import { review } from "./fixtures";

const N = 1000;
const same = (id: number) => id;

/** Do `edit` the way the page does: record its change, then apply it. */
function perform(state: { r: Review; h: History }, edit: Edit) {
  const change = changeFor(state.r, edit);
  return { r: applyEdit(state.r, edit, N), h: record(state.h, change) };
}

function step(state: { r: Review; h: History }, which: typeof undo) {
  const result = which(state.h, state.r, same)!;
  const r = result.edits.reduce((acc, e) => applyEdit(acc, e, N), state.r);
  return { r, h: result.history, edits: result.edits };
}

const shape = (r: Review) => ({ cuts: r.cuts.map((c) => [c.id, c.fate, c.frame]), labels: r.segments.map((s) => [s.start, s.label]) });

describe("transitionEdits", () => {
  it("test_it_deletes_with_one_edit", () => {
    expect(transitionEdits(4, { fate: "accepted", frame: 10 }, { fate: "deleted", frame: 10 })).toEqual([{ kind: "fate", cutId: 4, fate: "deleted" }]);
  });

  it("test_it_moves_back_and_then_restores_the_fate_a_move_replaced", () => {
    expect(transitionEdits(4, { fate: "moved", frame: 30 }, { fate: "pending", frame: 10 })).toEqual([
      { kind: "move", cutId: 4, frame: 10 },
      { kind: "fate", cutId: 4, fate: "pending" },
    ]);
  });

  it("test_it_revives_a_deleted_cut_before_moving_it", () => {
    expect(transitionEdits(4, { fate: "deleted", frame: 10 }, { fate: "moved", frame: 30 })).toEqual([
      { kind: "fate", cutId: 4, fate: "accepted" },
      { kind: "move", cutId: 4, frame: 30 },
    ]);
  });

  it("test_it_expects_an_inserted_cut_to_stay_accepted_after_a_move", () => {
    expect(transitionEdits(4, { fate: "accepted", frame: 30 }, { fate: "accepted", frame: 10 }, "inserted")).toEqual([{ kind: "move", cutId: 4, frame: 10 }]);
  });

  it("test_it_does_nothing_when_already_there", () => {
    expect(transitionEdits(4, { fate: "moved", frame: 30 }, { fate: "moved", frame: 30 })).toEqual([]);
  });
});

describe("undo and redo", () => {
  it("test_it_undoes_every_kind_of_edit_back_to_the_start_and_redoes_them_all", () => {
    const start = { r: review(), h: emptyHistory() };
    let s = perform(start, { kind: "fate", cutId: 1, fate: "accepted" });
    s = perform(s, { kind: "move", cutId: 2, frame: 520 });
    s = perform(s, { kind: "fate", cutId: 3, fate: "deleted" });
    s = perform(s, { kind: "insert", frame: 650, tempId: -1 });
    s = perform(s, { kind: "label", start: 520, stop: 650, label: "kick" });
    const end = s.r;
    let u = { r: s.r, h: s.h };
    for (let i = 0; i < 5; i++) u = step(u, undo);
    // The inserted cut stays in the review as deleted; everything else is as it began.
    expect(shape(u.r).cuts.filter(([id]) => id !== -1)).toEqual(shape(start.r).cuts);
    expect(u.r.cuts.find((c) => c.id === -1)?.fate).toBe("deleted");
    expect(shape(u.r).labels).toEqual(shape(start.r).labels);
    expect(undo(u.h, u.r, same)).toBeNull();
    for (let i = 0; i < 5; i++) u = step(u, redo);
    expect(shape(u.r)).toEqual(shape(end));
    expect(redo(u.h, u.r, same)).toBeNull();
  });

  it("test_it_forgets_the_redo_branch_after_a_new_edit", () => {
    let s = perform({ r: review(), h: emptyHistory() }, { kind: "fate", cutId: 1, fate: "accepted" });
    const u = step(s, undo);
    s = perform({ r: u.r, h: u.h }, { kind: "fate", cutId: 2, fate: "deleted" });
    expect(s.h.future).toEqual([]);
    expect(s.h.past.map((c) => c.title)).toEqual(["delete cut at 500"]);
  });

  it("test_it_undoes_an_insert_by_deleting_the_server_id", () => {
    const s = perform({ r: review(), h: emptyHistory() }, { kind: "insert", frame: 650, tempId: -1 });
    const saved = { ...s.r, cuts: s.r.cuts.map((c) => (c.id === -1 ? { ...c, id: 40 } : c)) };
    const result = undo(s.h, saved, (id) => (id === -1 ? 40 : id))!;
    expect(result.edits).toEqual([{ kind: "fate", cutId: 40, fate: "deleted" }]);
  });

  it("test_it_refuses_to_undo_a_label_whose_segment_is_gone", () => {
    let s = perform({ r: review(), h: emptyHistory() }, { kind: "label", start: 200, stop: 500, label: "kick" });
    s = { r: applyEdit(s.r, { kind: "fate", cutId: 2, fate: "deleted" }, N), h: s.h };
    expect(() => undo(s.h, s.r, same)).toThrow(/Segment 200–500 no longer exists/);
  });

  it("test_it_titles_each_step_for_the_user", () => {
    const r = review();
    expect(changeFor(r, { kind: "move", cutId: 1, frame: 230 }).title).toBe("move cut 200 → 230");
    expect(changeFor(r, { kind: "fate", cutId: 1, fate: "accepted" }).title).toBe("accept cut at 200");
    expect(changeFor(r, { kind: "label", start: 0, stop: 200, label: null }).title).toBe("clear label");
    const deleted = applyEdit(r, { kind: "fate", cutId: 2, fate: "deleted" }, N);
    expect(changeFor(deleted, { kind: "fate", cutId: 2, fate: "pending" }).title).toBe("restore cut at 500");
  });

  it("test_it_keeps_at_most_the_history_limit", () => {
    let h = emptyHistory();
    const change = changeFor(review(), { kind: "fate", cutId: 1, fate: "accepted" });
    for (let i = 0; i < 12; i++) h = record(h, change, 10);
    expect(h.past).toHaveLength(10);
  });
});
