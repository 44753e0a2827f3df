import { describe, expect, it } from "vitest";
import { clampView, follow, formatTime, frameToX, fullView, MIN_SPAN, panBy, snapFrame, ticks, tickStep, xToFrame, zoomAround } from "../src/review/timescale";

describe("time axis", () => {
  it("test_it_maps_frames_to_pixels_and_back", () => {
    const v = { start: 1000, span: 2000, width: 800, nFrames: 72000 };
    expect(frameToX(v, 1000)).toBe(0);
    expect(frameToX(v, 3000)).toBe(800);
    expect(xToFrame(v, frameToX(v, 1234.5))).toBeCloseTo(1234.5, 9);
  });

  it("test_it_snaps_to_whole_frames_inside_the_take", () => {
    const v = fullView(100, 1000);
    expect(snapFrame(v, 104)).toBe(10);
    expect(snapFrame(v, 106)).toBe(11);
    expect(snapFrame(v, -50)).toBe(0);
    expect(snapFrame(v, 5000)).toBe(99);
  });

  it("test_it_zooms_keeping_the_frame_under_the_cursor_fixed", () => {
    const v = fullView(72000, 1000);
    const before = xToFrame(v, 250);
    const z = zoomAround(v, 250, 0.1);
    expect(z.span).toBeCloseTo(7200);
    expect(xToFrame(z, 250)).toBeCloseTo(before, 6);
  });

  it("test_it_never_zooms_past_the_take_or_below_the_minimum_span", () => {
    const v = fullView(72000, 1000);
    expect(zoomAround(v, 500, 10)).toEqual(v);
    expect(zoomAround(v, 500, 1e-9).span).toBe(MIN_SPAN);
  });

  it("test_it_pans_by_pixels_and_stops_at_the_edges", () => {
    const v = { start: 1000, span: 1000, width: 500, nFrames: 5000 };
    expect(panBy(v, -100).start).toBe(1200);
    expect(panBy(v, 10000).start).toBe(0);
    expect(panBy(v, -1e6).start).toBe(4000);
  });

  it("test_it_scrolls_to_keep_the_playhead_in_view", () => {
    const v = { start: 0, span: 1000, width: 500, nFrames: 5000 };
    expect(follow(v, 500)).toBe(v);
    expect(follow(v, 1500).start).toBe(550);
    expect(clampView({ ...v, start: -20 }).start).toBe(0);
  });

  it("test_it_places_ticks_on_round_times_at_least_min_px_apart", () => {
    const v = fullView(72000, 1200);
    const step = tickStep(v, 120);
    expect(step * (1200 / 72000)).toBeGreaterThanOrEqual(80);
    expect(step % 120).toBe(0);
    const t = ticks(v, 120);
    expect(t[0]).toBe(0);
    expect(t[1] - t[0]).toBe(step);
  });

  it("test_it_writes_time_in_minutes_seconds_and_hundredths", () => {
    expect(formatTime(1234, 120)).toBe("0:10.28");
    expect(formatTime(72000, 120)).toBe("10:00.00");
    expect(formatTime(7199.9, 120)).toBe("1:00.00");
    expect(formatTime(0, 30)).toBe("0:00.00");
  });
});
