import { describe, expect, it } from "vitest";
import type { ReviewComment, SegmentAttribute } from "../src/api/types";
import { commandFor, HELP, type KeyInput } from "../src/review/keymap";
import { neighbourComment, nextValue, threadsInOrder } from "../src/review/notes";
import { applyEdit, labelRequest } from "../src/review/state";
import { review } from "./fixtures";

const key = (k: string, mods: Partial<KeyInput> = {}): KeyInput => ({ key: k, shiftKey: false, ctrlKey: false, metaKey: false, altKey: false, ...mods });

const comment = (id: number, frame: number, parent: number | null = null): ReviewComment => ({
  id, review: 7, annotator: "ann", author: "ann", parent, anchor: "frame", cut: null, frame, text: `c${id}`,
  created_at: "2026-01-01T00:00:00Z", resolved: false, resolved_by: null,
});

const quality: SegmentAttribute = { id: 1, name: "quality", kind: "choice", options: ["good", "usable", "unusable"], hotkey: "q", position: 0, in_use: 0 };
const cleanup: SegmentAttribute = { id: 2, name: "needs cleanup", kind: "boolean", options: [], hotkey: "b", position: 1, in_use: 0 };

describe("comments", () => {
  const comments = [comment(1, 300), comment(2, 100), comment(3, 100, 2), comment(4, 300)];

  it("test_it_lists_threads_by_frame_without_their_replies", () => {
    expect(threadsInOrder(comments).map((c) => c.id)).toEqual([2, 1, 4]);
  });

  it("test_it_jumps_to_the_next_and_previous_thread_strictly_past_the_playhead", () => {
    expect(neighbourComment(comments, 0, 1)?.frame).toBe(100);
    expect(neighbourComment(comments, 100, 1)?.id).toBe(1);
    expect(neighbourComment(comments, 300, 1)).toBeUndefined();
    expect(neighbourComment(comments, 300, -1)?.id).toBe(2);
  });

  it("test_c_and_m_are_the_comment_keys", () => {
    expect(commandFor(key("c"))).toEqual({ kind: "comment", on: "playhead" });
    expect(commandFor(key("m"))).toEqual({ kind: "commentJump", direction: 1 });
    expect(commandFor(key("M", { shiftKey: true }))).toEqual({ kind: "commentJump", direction: -1 });
    expect(HELP.some(([keys]) => keys.startsWith("M / Shift+M"))).toBe(true);
  });
});

describe("attributes", () => {
  it("test_an_attribute_letter_is_a_command_only_when_an_attribute_has_it", () => {
    expect(commandFor(key("q"))).toBeNull();
    expect(commandFor(key("q"), "qb")).toEqual({ kind: "attribute", hotkey: "q", back: false });
    expect(commandFor(key("Q", { shiftKey: true }), "qb")).toEqual({ kind: "attribute", hotkey: "q", back: true });
    // Keys of other commands stay theirs.
    expect(commandFor(key("a"), "a")).toEqual({ kind: "accept" });
  });

  it("test_a_choice_key_cycles_its_options_then_clears", () => {
    expect(nextValue(quality, undefined)).toBe("good");
    expect(nextValue(quality, "good")).toBe("usable");
    expect(nextValue(quality, "unusable")).toBeNull();
    expect(nextValue(quality, undefined, true)).toBe("unusable");
    expect(nextValue(cleanup, undefined)).toBe(true);
    expect(nextValue(cleanup, true)).toBe(false);
  });

  it("test_an_attribute_edit_shows_at_once_and_is_sent_by_segment_index", () => {
    const edit = { kind: "attribute" as const, start: 200, stop: 500, name: "quality", value: "good" };
    const after = applyEdit(review(), edit, 1000);
    expect(after.segments[1].attributes).toEqual({ quality: "good" });
    expect(labelRequest(3, review(), edit, 4)).toEqual({
      method: "PATCH", url: "/api/captures/3/review/segments/1/attributes/", body: { name: "quality", value: "good", version: 4 },
    });
    const cleared = applyEdit(after, { ...edit, value: null }, 1000);
    expect(cleared.segments[1].attributes).toEqual({});
  });
});

describe("attributes on screen", () => {
  it("test_a_value_follows_its_segment_when_a_cut_moves_before_the_server_answers", () => {
    const r = review();
    r.segments[1] = { ...r.segments[1], attributes: { quality: "good" } };
    const moved = applyEdit(r, { kind: "move", cutId: 1, frame: 250 }, 1000);
    expect(moved.segments[1]).toMatchObject({ start: 250, attributes: { quality: "good" } });
    expect(moved.segments[0].attributes).toEqual({});
  });

  it("test_shift_c_comments_on_the_segment", () => {
    expect(commandFor(key("C", { shiftKey: true }))).toEqual({ kind: "comment", on: "segment" });
  });
});
