import { describe, expect, it } from "vitest";
import { denseCuts, DRAG_THRESHOLD_PX, density, hitHandle, isDrag, overviewFrame, overviewX, rows, zoneAt, HANDLES, RULER } from "../src/review/hits";
import { MinMaxPyramid, quantile, robustRange } from "../src/review/lanes";
import { fullView, LONG_TAKE_SECONDS, openingView, pageFollow, WINDOW_SECONDS } from "../src/review/timescale";

/** Min and max of the samples starting in each column, the obvious way. */
function naiveColumns(values: number[], first: number, perPx: number, width: number): [number, number][] {
  const out: [number, number][] = Array.from({ length: width }, () => [NaN, NaN]);
  values.forEach((v, i) => {
    const c = Math.floor((i - first) / perPx);
    if (c < 0 || c >= width || !Number.isFinite(v)) return;
    out[c] = [Number.isNaN(out[c][0]) ? v : Math.min(out[c][0], v), Number.isNaN(out[c][1]) ? v : Math.max(out[c][1], v)];
  });
  return out;
}

function seeded(n: number, seed = 7): number[] {
  let s = seed;
  return Array.from({ length: n }, () => {
    s = (s * 1103515245 + 12345) % 2147483648;
    return s / 2147483648;
  });
}

describe("lane scaling", () => {
  it("test_it_keeps_the_full_range_of_an_ordinary_signal", () => {
    const values = seeded(5000).map((v, i) => Math.sin(i / 50) * 10 + v);
    const r = robustRange(values);
    expect(r.lo).toBe(Math.min(...values));
    expect(r.hi).toBe(Math.max(...values));
    expect(r.clippedHigh || r.clippedLow).toBe(false);
  });

  it("test_it_clips_a_t_pose_spike_instead_of_flattening_the_lane", () => {
    // 13_29_blender.fbx: the T-pose frame's speed 193,053 against a median of 3,760.
    const values = seeded(4593).map((v) => 2000 + 3500 * v);
    values[0] = 193_053;
    const r = robustRange(values);
    expect(r.clippedHigh).toBe(true);
    expect(r.clippedLow).toBe(false);
    expect(r.hi).toBeLessThan(6000);
    expect(r.hi).toBeGreaterThan(quantile([...values].sort((a, b) => a - b), 0.99));
    // The bulk of the signal spans most of the lane's height, not 2 % of it.
    expect((5500 - 2000) / (r.hi - r.lo)).toBeGreaterThan(0.8);
  });

  it("test_it_clips_a_spike_downwards_too_and_ignores_gaps", () => {
    const values = [...seeded(1000).map((v) => 10 + v), NaN, -Infinity, -500];
    const r = robustRange(values);
    expect(r.clippedLow).toBe(true);
    expect(r.lo).toBeGreaterThan(9);
  });

  it("test_it_widens_flat_and_empty_signals", () => {
    expect(robustRange([2, 2, NaN])).toEqual({ lo: 1.5, hi: 2.5, clippedLow: false, clippedHigh: false });
    expect(robustRange([])).toEqual({ lo: 0, hi: 1, clippedLow: false, clippedHigh: false });
  });
});

describe("decimation to a min-max per pixel column", () => {
  it("test_it_matches_the_obvious_reduction_when_columns_hold_whole_blocks", () => {
    const values = seeded(4096).map((v) => v * 100);
    const p = new MinMaxPyramid(values);
    const { min, max } = p.columns(0, 16, 256);
    const naive = naiveColumns(values, 0, 16, 256);
    naive.forEach(([lo, hi], c) => {
      expect(min[c]).toBeCloseTo(lo, 3);
      expect(max[c]).toBeCloseTo(hi, 3);
    });
  });

  it("test_it_never_loses_a_one_frame_spike_at_any_zoom", () => {
    const values = seeded(432_000);
    values[123_457] = 50;
    const p = new MinMaxPyramid(values);
    for (const perPx of [2.3, 17, 300.5, 432_000 / 1400]) {
      const { max } = p.columns(0, perPx, Math.ceil(432_000 / perPx));
      const c = max.indexOf(50);
      expect(c).toBeGreaterThanOrEqual(0);
      // In the column of the spike's frame, or of its block's start (less than a pixel before).
      expect([Math.floor(123_457 / perPx) - 1, Math.floor(123_457 / perPx)]).toContain(c);
    }
  });

  it("test_it_costs_the_width_not_the_take", () => {
    const p = new MinMaxPyramid(seeded(432_000));
    const { min } = p.columns(1000, 432_000 / 1400, 1400);
    expect(min.length).toBe(1400);
    expect(p.levels[Math.floor(Math.log2(432_000 / 1400))].min.length).toBeLessThan(2000);
  });

  it("test_it_leaves_columns_without_finite_samples_empty", () => {
    const p = new MinMaxPyramid([1, NaN, NaN, NaN, 3, 4]);
    const { min, max } = p.columns(0, 2, 3);
    expect([min[0], max[0]]).toEqual([1, 1]);
    expect(Number.isNaN(min[1])).toBe(true);
    expect([min[2], max[2]]).toEqual([3, 4]);
  });
});

describe("timeline hit-testing", () => {
  const r = rows(2);
  const handleY = RULER + HANDLES / 2;
  const cuts = [{ id: 1, x: 100 }, { id: 2, x: 108 }, { id: 3, x: 400 }];

  it("test_a_press_on_the_ruler_never_grabs_a_cut_even_right_above_one", () => {
    for (let y = 0; y < RULER; y++) {
      expect(zoneAt(r, y)).toBe("ruler");
      expect(hitHandle(r, cuts, 100, y, false, null)).toBeNull();
    }
  });

  it("test_a_cut_is_grabbed_only_on_its_handle", () => {
    expect(hitHandle(r, cuts, 400, handleY, false, null)).toBe(3);
    expect(hitHandle(r, cuts, 405, handleY, false, null)).toBe(3);
    expect(hitHandle(r, cuts, 408, handleY, false, null)).toBeNull();
    // The lanes and the overview show the cut's line but never grab it.
    for (const y of [r.lanes[0].top + 10, r.lanes[1].top + 30, r.segTop + 5, r.overviewTop + 5]) {
      expect(hitHandle(r, cuts, 400, y, false, null)).toBeNull();
    }
  });

  it("test_of_two_handles_the_nearer_wins_and_the_selected_on_a_tie", () => {
    expect(hitHandle(r, cuts, 103, handleY, false, null)).toBe(1);
    expect(hitHandle(r, cuts, 106, handleY, false, null)).toBe(2);
    expect(hitHandle(r, cuts, 104, handleY, false, 2)).toBe(2);
  });

  it("test_no_handle_is_grabbed_while_the_cuts_are_too_dense", () => {
    expect(denseCuts(564, 1400)).toBe(true);
    expect(denseCuts(94, 1400)).toBe(false);
    expect(denseCuts(0, 1400)).toBe(false);
    expect(hitHandle(r, cuts, 400, handleY, true, null)).toBeNull();
  });

  it("test_a_handle_moves_only_past_the_drag_threshold", () => {
    expect(isDrag(100, 100 + DRAG_THRESHOLD_PX)).toBe(false);
    expect(isDrag(100, 100 - DRAG_THRESHOLD_PX - 1)).toBe(true);
  });
});

describe("overview and working window", () => {
  it("test_the_overview_maps_the_whole_take_to_its_width", () => {
    expect(overviewFrame(0, 1400, 432_000)).toBe(0);
    expect(overviewFrame(700, 1400, 432_000)).toBe(216_000);
    expect(overviewFrame(5000, 1400, 432_000)).toBe(431_999);
    expect(overviewFrame(overviewX(123_456, 1400, 432_000), 1400, 432_000)).toBe(123_456);
  });

  it("test_the_overview_counts_candidates_per_pixel_column", () => {
    const d = density([0, 10, 99, 431_999], 4, 432_000);
    expect(Array.from(d)).toEqual([3, 0, 0, 1]);
  });

  it("test_a_long_take_opens_on_a_working_window_and_a_short_one_whole", () => {
    expect(openingView(4593, 120, 1400)).toEqual(fullView(4593, 1400));
    const hour = openingView(432_000, 120, 1400, 200_000);
    expect(hour.span).toBe(WINDOW_SECONDS * 120);
    expect(hour.start).toBeLessThanOrEqual(200_000);
    expect(hour.start + hour.span).toBeGreaterThan(200_000);
    expect(openingView(LONG_TAKE_SECONDS * 120, 120, 1400).span).toBe(LONG_TAKE_SECONDS * 120);
  });

  it("test_the_working_window_turns_a_page_only_when_the_playhead_leaves_it", () => {
    const v = { start: 12_000, span: 7200, width: 1400, nFrames: 432_000 };
    expect(pageFollow(v, 12_000)).toBe(v);
    expect(pageFollow(v, 19_200)).toBe(v);
    const next = pageFollow(v, 19_201);
    expect(next.start).toBeLessThan(19_201);
    expect(next.start + next.span * 0.9).toBeGreaterThan(19_201);
    const back = pageFollow(v, 11_000);
    expect(back.start + back.span).toBeGreaterThan(11_000);
    expect(back.start + back.span * 0.9).toBeLessThan(11_000);
  });
});
