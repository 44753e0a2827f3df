import { afterEach, describe, expect, it, vi } from "vitest";
import type { FramesResponse } from "../src/api/types";
import { decodeFloat32, FrameStore, loadFrames, planChunks, planPoses, posesAsJson } from "../src/review/frames";

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

describe("planPoses", () => {
  it("test_it_asks_for_a_small_head_at_the_playhead_then_after_it_then_before_it", () => {
    expect(planPoses(432000, 12345, 600)).toEqual([{ start: 12345, stop: 12945 }, { start: 12945, stop: 432000 }, { start: 0, stop: 12345 }]);
    expect(planPoses(432000, 0, 600)).toEqual([{ start: 0, stop: 600 }, { start: 600, stop: 432000 }]);
  });

  it("test_it_keeps_the_head_inside_the_take", () => {
    expect(planPoses(1000, 990, 600)).toEqual([{ start: 400, stop: 1000 }, { start: 0, stop: 400 }]);
    expect(planPoses(400, 0, 600)).toEqual([{ start: 0, stop: 400 }]);
  });
});

describe("FrameStore.receive", () => {
  it("test_it_counts_a_frame_only_when_all_its_bytes_are_in_even_split_inside_a_value", () => {
    const store = new FrameStore(6, 1);
    const bytes = new Uint8Array(new Float32Array([...Array(9).keys()].map((i) => i + 0.5)).buffer); // frames 2, 3, 4
    store.receive(2, 0, bytes.subarray(0, 13)); // frame 2 and one byte of frame 3
    expect(store.loadedFrames).toBe(1);
    expect(store.has(2) && !store.has(3)).toBe(true);
    store.receive(2, 13, bytes.subarray(13, 30));
    expect([store.has(3), store.has(4)]).toEqual([true, false]);
    store.receive(2, 30, bytes.subarray(30));
    expect(store.loadedFrames).toBe(3);
    expect([...store.pose(4)]).toEqual([6.5, 7.5, 8.5]);
  });

  it("test_it_refuses_bytes_past_the_last_frame", () => {
    const store = new FrameStore(2, 1);
    expect(() => store.receive(1, 0, new Uint8Array(24))).toThrow(/run past frame 2/);
  });
});

/** A fetch that answers /poses/ from `take` ((n_frames, n_joints * 3) values), in pieces of `piece` bytes. */
function posesServer(take: Float32Array, nJoints: number, piece = 7) {
  const asked: string[] = [];
  const fetcher = async (url: string) => {
    asked.push(url);
    const q = new URL(url, "http://x").searchParams;
    const start = Number(q.get("start"));
    const stop = Number(q.get("stop"));
    const bytes = new Uint8Array(take.slice(start * nJoints * 3, stop * nJoints * 3).buffer);
    const body = new ReadableStream<Uint8Array>({
      start(controller) {
        for (let i = 0; i < bytes.length; i += piece) controller.enqueue(bytes.slice(i, i + piece));
        controller.close();
      },
    });
    return new Response(body, { status: 200, headers: { "X-Poses-Joints": String(nJoints) } });
  };
  return { asked, fetcher };
}

describe("loadFrames", () => {
  const realFetch = globalThis.fetch;
  afterEach(() => {
    globalThis.fetch = realFetch;
  });

  it("test_it_fills_every_pose_from_the_head_and_two_streamed_answers", async () => {
    const take = new Float32Array(900 * 2 * 3).map((_, i) => i);
    const server = posesServer(take, 2);
    globalThis.fetch = server.fetcher as typeof fetch;
    const store = new FrameStore(900, 2);
    let release = () => {};
    const gate = new Promise<void>((resolve) => (release = resolve));
    let chunks = 0;
    const done = loadFrames(7, store, 100, () => chunks++, undefined, gate);
    await vi.waitFor(() => expect(chunks).toBe(1));
    // The head alone until the page lets the rest come.
    expect(server.asked).toEqual(["/api/captures/7/poses/?start=100&stop=700"]);
    expect(store.loadedFrames).toBe(600);
    release();
    await done;
    expect(server.asked.slice(1)).toEqual(["/api/captures/7/poses/?start=700&stop=900", "/api/captures/7/poses/?start=0&stop=100"]);
    expect(store.loadedFrames).toBe(900);
    expect(store.error).toBeNull();
    expect(store.positions).toEqual(take);
  });

  it("test_it_shows_the_servers_own_words_when_it_refuses", async () => {
    globalThis.fetch = (async () =>
      new Response(JSON.stringify({ detail: "capture 7 is processing; it has no poses yet" }), { status: 400 })) as typeof fetch;
    const store = new FrameStore(10, 1);
    await loadFrames(7, store, 0, () => {});
    expect(store.error).toBe("capture 7 is processing; it has no poses yet");
  });

  it("test_it_names_an_answer_of_the_wrong_skeleton", async () => {
    globalThis.fetch = posesServer(new Float32Array(10 * 3 * 3), 3).fetcher as typeof fetch;
    const store = new FrameStore(10, 2);
    await loadFrames(7, store, 0, () => {});
    expect(store.error).toBe("Poses 0–10: expected 2 joints, got 3.");
  });

  it("test_it_names_an_answer_cut_short", async () => {
    globalThis.fetch = (async () => new Response(new Uint8Array(12 * 4), { status: 200, headers: { "X-Poses-Joints": "1" } })) as typeof fetch;
    const store = new FrameStore(10, 1);
    await loadFrames(7, store, 0, () => {});
    expect(store.error).toBe("Poses 0–10: expected 120 bytes, got 48.");
  });

  it("test_it_keeps_the_json_chunks_for_poses_json", () => {
    expect(posesAsJson("?poses=json")).toBe(true);
    expect(posesAsJson("")).toBe(false);
  });
});
