import { describe, expect, it } from "vitest";
import type { FramesResponse } from "../src/api/types";
import { decodeFloat32, FrameStore, planChunks } from "../src/review/frames";

function base64(bytes: Uint8Array): string {
  return btoa(String.fromCharCode(...bytes));
}

function encode(values: number[]): string {
  return base64(new Uint8Array(new Float32Array(values).buffer));
}

function chunk(start: number, stop: number, nJoints: number, fill: (frame: number, k: number) => number): FramesResponse {
  const values: number[] = [];
  for (let f = start; f < stop; f++) for (let k = 0; k < nJoints * 3; k++) values.push(fill(f, k));
  return { start, stop, step: 1, n_frames: stop - start, n_joints: nJoints, dtype: "float32", data: encode(values) };
}

describe("decodeFloat32", () => {
  it("test_it_decodes_little_endian_float32_from_base64", () => {
    // 1.5 as little-endian float32 is 00 00 c0 3f.
    expect([...decodeFloat32(base64(new Uint8Array([0, 0, 0xc0, 0x3f, 0, 0, 0x80, 0xbf])))]).toEqual([1.5, -1]);
  });

  it("test_it_rejects_a_payload_that_is_not_whole_floats", () => {
    expect(() => decodeFloat32(base64(new Uint8Array([1, 2, 3])))).toThrow(/3 bytes/);
  });
});

describe("planChunks", () => {
  it("test_it_covers_a_ten_minute_take_in_chunks_of_at_most_5000_frames", () => {
    const chunks = planChunks(72000);
    expect(chunks).toHaveLength(15);
    expect(chunks.every((c) => c.stop - c.start <= 5000)).toBe(true);
    const covered = chunks.slice().sort((a, b) => a.start - b.start);
    expect(covered[0].start).toBe(0);
    expect(covered[covered.length - 1].stop).toBe(72000);
    covered.slice(1).forEach((c, i) => expect(c.start).toBe(covered[i].stop));
  });

  it("test_it_asks_for_a_small_head_first_then_the_rest_of_its_chunk", () => {
    expect(planChunks(72000, 0, 5000, 600).slice(0, 3)).toEqual([{ start: 0, stop: 600 }, { start: 600, stop: 5000 }, { start: 5000, stop: 10000 }]);
    const mid = planChunks(30000, 12345, 5000, 600);
    expect(mid.slice(0, 3)).toEqual([{ start: 12345, stop: 12945 }, { start: 10000, stop: 12345 }, { start: 12945, stop: 15000 }]);
    const covered = mid.slice().sort((a, b) => a.start - b.start);
    covered.slice(1).forEach((c, i) => expect(c.start).toBe(covered[i].stop));
    expect(planChunks(400, 0, 5000, 600)).toEqual([{ start: 0, stop: 400 }]);
  });

  it("test_it_fetches_the_chunk_under_the_playhead_first_then_its_neighbours", () => {
    expect(planChunks(30000, 12345).slice(0, 3).map((c) => c.start)).toEqual([10000, 5000, 15000]);
  });
});

describe("FrameStore", () => {
  it("test_it_places_each_chunk_at_its_frames_and_counts_what_is_loaded", () => {
    const store = new FrameStore(10, 2);
    store.put(chunk(5, 10, 2, (f, k) => f * 100 + k));
    expect(store.loadedFrames).toBe(5);
    expect(store.has(4)).toBe(false);
    expect([...store.pose(7)]).toEqual([700, 701, 702, 703, 704, 705]);
    expect(store.nearestLoaded(2)).toBe(5);
    expect(store.nearestLoaded(9)).toBe(9);
  });

  it("test_it_names_the_chunk_whose_shape_is_wrong", () => {
    const store = new FrameStore(10, 3);
    expect(() => store.put(chunk(0, 5, 2, () => 0))).toThrow(/Frames 0–5: expected 5 × 3 joints × 3 values, got 30/);
  });
});

describe("floorLevel", () => {
  it("test_it_puts_the_floor_at_the_lowest_loaded_joint", () => {
    const store = new FrameStore(8, 2);
    expect(store.floorLevel()).toBeNull();
    store.put(chunk(0, 8, 2, (f, k) => (k % 3 === 1 ? -3 - f / 4 : 50)));
    expect(store.floorLevel()).toBe(-3 - 4 / 4);
  });

  it("test_it_skips_points_not_seen_in_a_frame", () => {
    const store = new FrameStore(8, 2);
    // Point 0 is a gap (NaN) in every frame; point 1 is seen at height -2.
    store.put(chunk(0, 8, 2, (_f, k) => (k < 3 ? Number.NaN : k % 3 === 1 ? -2 : 50)));
    expect(store.floorLevel()).toBe(-2);
  });
});
