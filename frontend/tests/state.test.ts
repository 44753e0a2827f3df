import { describe, expect, it } from "vitest";
import type { Review } from "../src/api/types";
import { applyEdit, deriveSegments, labelsByStartCut, describeDifferences, editRequest, EditError, findInsertedId, labelRequest, nearestDeleted, neighbourCut, neighbourPending, neighbourUnlabelled, segmentAt, startedIds, withTempIds } from "../src/review/state";
import { cut, review } from "./fixtures";

const N = 1000;
const same = (id: number) => id;

describe("deriveSegments", () => {
  it("test_it_splits_the_take_at_every_cut_that_is_not_deleted", () => {
    const segments = deriveSegments([cut(1, 500), cut(2, 200, "accepted"), cut(3, 800, "deleted")], N);
    expect(segments.map((s) => [s.index, s.start, s.stop])).toEqual([[0, 0, 200], [1, 200, 500], [2, 500, 1000]]);
  });

  it("test_it_returns_one_segment_for_a_take_without_cuts", () => {
    expect(deriveSegments([], N)).toEqual([{ index: 0, start: 0, stop: N, label: null }]);
  });

  it("test_it_asks_for_each_label_by_the_cut_that_starts_the_segment", () => {
    const labels = new Map<number | null, string>([[null, "walk"], [2, "punch"]]);
    const segments = deriveSegments([cut(2, 500), cut(1, 200)], N, (id) => labels.get(id) ?? null);
    expect(segments.map((s) => s.label)).toEqual(["walk", null, "punch"]);
  });

  it("test_it_keys_labels_by_start_cut_the_way_the_server_stores_them", () => {
    expect([...labelsByStartCut(review()).entries()]).toEqual([[null, "walk"], [1, null], [2, "punch"], [3, null]]);
  });
});

describe("applyEdit", () => {
  it("test_it_accepts_a_candidate_without_touching_the_others", () => {
    const next = applyEdit(review(), { kind: "fate", cutId: 2, fate: "accepted" }, N);
    expect(next.cuts.map((c) => c.fate)).toEqual(["pending", "accepted", "pending"]);
    expect(review().cuts[1].fate).toBe("pending");
  });

  it("test_it_merges_segments_when_a_cut_is_deleted_keeping_the_earlier_label", () => {
    const next = applyEdit(review(), { kind: "fate", cutId: 1, fate: "deleted" }, N);
    expect(next.segments.map((s) => [s.start, s.stop, s.label])).toEqual([[0, 500, "walk"], [500, 800, "punch"], [800, N, null]]);
  });

  it("test_it_moves_a_label_with_the_cut_that_starts_its_segment", () => {
    const next = applyEdit(review(), { kind: "move", cutId: 2, frame: 550 }, N);
    expect(next.segments.map((s) => [s.start, s.stop, s.label])).toEqual([[0, 200, "walk"], [200, 550, null], [550, 800, "punch"], [800, N, null]]);
  });

  it("test_it_leaves_the_new_half_of_a_split_segment_unlabelled", () => {
    const next = applyEdit(review(), { kind: "insert", frame: 650, tempId: -1 }, N);
    expect(next.segments.map((s) => s.label)).toEqual(["walk", null, "punch", null, null]);
  });

  it("test_it_keeps_an_inserted_cut_accepted_when_it_moves", () => {
    const inserted = applyEdit(review(), { kind: "insert", frame: 650, tempId: -1 }, N);
    expect(applyEdit(inserted, { kind: "move", cutId: -1, frame: 660 }, N).cuts.find((c) => c.id === -1)?.fate).toBe("accepted");
  });

  it("test_it_marks_a_moved_cut_moved_and_keeps_its_candidate_frame", () => {
    const next = applyEdit(review(), { kind: "move", cutId: 1, frame: 230 }, N);
    expect(next.cuts[0]).toMatchObject({ fate: "moved", frame: 230, candidate_frame: 200 });
    expect(next.segments[0]).toMatchObject({ start: 0, stop: 230, label: "walk" });
  });

  it("test_it_inserts_a_cut_with_the_temporary_id", () => {
    const next = applyEdit(review(), { kind: "insert", frame: 650, tempId: -1 }, N);
    expect(next.cuts.find((c) => c.id === -1)).toMatchObject({ origin: "inserted", fate: "accepted", frame: 650 });
    expect(next.segments).toHaveLength(5);
  });

  it("test_it_refuses_a_cut_outside_the_take", () => {
    expect(() => applyEdit(review(), { kind: "insert", frame: 0, tempId: -1 }, N)).toThrow(/inside the take \(1–999\), not at frame 0/);
    expect(() => applyEdit(review(), { kind: "move", cutId: 1, frame: N }, N)).toThrow(EditError);
  });

  it("test_it_refuses_a_second_cut_on_the_same_frame", () => {
    expect(() => applyEdit(review(), { kind: "insert", frame: 500, tempId: -1 }, N)).toThrow(/already a cut at frame 500/);
  });

  it("test_it_allows_inserting_where_a_deleted_cut_was", () => {
    const r = review([cut(1, 500, "deleted")]);
    expect(applyEdit(r, { kind: "insert", frame: 500, tempId: -1 }, N).segments).toHaveLength(2);
  });

  it("test_it_labels_the_segment_with_those_bounds", () => {
    const next = applyEdit(review(), { kind: "label", start: 200, stop: 500, label: "squat" }, N);
    expect(next.segments.map((s) => s.label)).toEqual(["walk", "squat", "punch", null]);
  });

  it("test_it_refuses_to_restore_a_deleted_cut_onto_a_kept_one", () => {
    const r = review([cut(1, 500, "deleted"), { ...cut(2, 500, "accepted"), origin: "inserted" }]);
    expect(() => applyEdit(r, { kind: "fate", cutId: 1, fate: "pending" }, N)).toThrow("Cannot restore the cut at frame 500: another cut is there now.");
    expect(applyEdit(review([cut(1, 500, "deleted")]), { kind: "fate", cutId: 1, fate: "pending" }, N).segments).toHaveLength(2);
  });

  it("test_it_names_the_unknown_cut", () => {
    expect(() => applyEdit(review(), { kind: "fate", cutId: 99, fate: "accepted" }, N)).toThrow("Cut 99 is not in this review.");
  });
});

describe("requests", () => {
  it("test_it_sends_the_version_with_every_edit", () => {
    expect(editRequest(3, { kind: "fate", cutId: 2, fate: "deleted" }, 9, same)).toEqual({
      method: "PATCH", url: "/api/captures/3/review/cuts/2/", body: { fate: "deleted", version: 9 },
    });
    expect(editRequest(3, { kind: "move", cutId: 2, frame: 510 }, 9, same).body).toEqual({ frame: 510, version: 9 });
    expect(editRequest(3, { kind: "insert", frame: 42, tempId: -1 }, 9, same)).toEqual({
      method: "POST", url: "/api/captures/3/review/cuts/", body: { frame: 42, version: 9 },
    });
  });

  it("test_it_maps_a_temporary_id_to_the_server_id", () => {
    const map = new Map([[-1, 77]]);
    expect(editRequest(3, { kind: "fate", cutId: -1, fate: "deleted" }, 1, (id) => map.get(id) ?? id).url).toBe("/api/captures/3/review/cuts/77/");
  });

  it("test_it_addresses_a_label_by_the_index_the_server_holds_now", () => {
    const r = review();
    expect(labelRequest(3, r, { kind: "label", start: 500, stop: 800, label: "kick" }, 4)).toEqual({
      method: "PATCH", url: "/api/captures/3/review/segments/2/", body: { label: "kick", version: 4 },
    });
    expect(() => labelRequest(3, r, { kind: "label", start: 500, stop: 700, label: "kick" }, 4)).toThrow(/500–700 no longer exists/);
  });

  it("test_it_finds_the_id_the_server_gave_an_inserted_cut", () => {
    const before = review();
    const after = { ...before, cuts: [...before.cuts, { ...cut(12, 650, "accepted"), origin: "inserted" as const }] };
    expect(findInsertedId(before, after, 650)).toBe(12);
    expect(findInsertedId(before, after, 651)).toBeUndefined();
  });
});

describe("navigation", () => {
  it("test_it_finds_the_neighbouring_cut_strictly_before_and_after", () => {
    const cuts = [cut(1, 200), cut(2, 500, "deleted"), cut(3, 800)];
    expect(neighbourCut(cuts, 200, 1)?.id).toBe(3);
    expect(neighbourCut(cuts, 800, -1)?.id).toBe(1);
    expect(neighbourCut(cuts, 200, -1)).toBeUndefined();
  });

  it("test_it_finds_the_neighbouring_pending_candidate_skipping_decided_cuts", () => {
    const cuts = [cut(1, 200, "accepted"), cut(2, 500), cut(3, 800, "deleted"), cut(4, 900)];
    expect(neighbourPending(cuts, 0, 1)?.id).toBe(2);
    expect(neighbourPending(cuts, 500, 1)?.id).toBe(4);
    expect(neighbourPending(cuts, 500, -1)).toBeUndefined();
  });

  it("test_it_finds_the_neighbouring_unlabelled_segment_by_its_start", () => {
    const segments = review().segments; // walk, —, punch, —
    expect(neighbourUnlabelled(segments, 0, 1)?.start).toBe(200);
    expect(neighbourUnlabelled(segments, 200, 1)?.start).toBe(800);
    expect(neighbourUnlabelled(segments, 900, -1)?.start).toBe(800);
    expect(neighbourUnlabelled(segments, 800, -1)?.start).toBe(200);
    expect(neighbourUnlabelled(segments, 800, 1)).toBeUndefined();
  });

  it("test_it_finds_the_deleted_candidate_nearest_a_frame_not_a_deleted_inserted_cut", () => {
    const inserted = { ...cut(5, 480, "deleted"), origin: "inserted" as const, candidate_frame: null };
    const cuts = [cut(1, 200, "deleted"), cut(2, 500), cut(3, 800, "deleted"), inserted];
    expect(nearestDeleted(cuts, 490)?.id).toBe(1);
    expect(nearestDeleted(cuts, 700)?.id).toBe(3);
    expect(nearestDeleted([cut(2, 500)], 700)).toBeUndefined();
  });

  it("test_it_finds_the_segment_under_a_frame_with_stop_exclusive", () => {
    const segments = review().segments;
    expect(segmentAt(segments, 199)?.index).toBe(0);
    expect(segmentAt(segments, 200)?.index).toBe(1);
    expect(segmentAt(segments, 999)?.index).toBe(3);
  });
});

describe("describeDifferences", () => {
  it("test_it_lists_what_another_session_changed", () => {
    const mine = review();
    const theirs = applyEdit(applyEdit(applyEdit(mine, { kind: "move", cutId: 1, frame: 210 }, N), { kind: "fate", cutId: 3, fate: "deleted" }, N), { kind: "label", start: 0, stop: 210, label: "run" }, N);
    theirs.cuts.push({ ...cut(9, 100, "accepted"), origin: "inserted" });
    expect(describeDifferences(mine, theirs)).toEqual([
      "cut at frame 200 is now at frame 210",
      "cut at frame 800 is deleted, not candidate",
      "cut at frame 100 was added (accepted)",
    ]);
    const relabelled = { ...mine, segments: mine.segments.map((s) => (s.index === 0 ? { ...s, label: "run" } : s)) };
    expect(describeDifferences(mine, relabelled)).toEqual(["segment 0–200 is labelled run, not walk"]);
  });

  it("test_it_says_nothing_when_nothing_changed", () => {
    expect(describeDifferences(review(), review())).toEqual([]);
  });
});

describe("an unstarted review", () => {
  const unstarted = (): Review => ({ ...review(), id: null, status: "not_started", version: 1, cuts: review().cuts.map((c) => ({ ...c, id: null as unknown as number })) });

  it("test_it_gives_the_candidates_of_an_unstarted_review_temporary_ids", () => {
    expect(withTempIds(unstarted()).cuts.map((c) => c.id)).toEqual([-1, -2, -3]);
    expect(withTempIds(review())).toEqual(review());
  });

  it("test_it_maps_temporary_ids_onto_the_started_reviews_cuts_by_candidate_frame", () => {
    const started = { ...review([cut(41, 800), cut(42, 200), cut(43, 500)]), id: 7 };
    expect([...startedIds(withTempIds(unstarted()), started).entries()]).toEqual([[-1, 42], [-2, 43], [-3, 41]]);
  });
});
