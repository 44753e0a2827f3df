import { describe, expect, it, vi } from "vitest";
import { PlaybackController } from "../src/player/playback";
import { halfFrame, JUMP_S, offsetFor, plan, takePosition, videoTime, type ClockState, type VideoState } from "../src/video/sync";

const clock = (over: Partial<ClockState> = {}): ClockState => ({ position: 240, playing: false, speed: 1, fps: 120, ...over });
const video = (over: Partial<VideoState> = {}): VideoState => ({ currentTime: 2, duration: 10, seeking: false, paused: true, ...over });

describe("reference video time", () => {
  it("test_video_time_is_take_time_plus_offset", () => {
    expect(videoTime(240, 120, 0.5)).toBeCloseTo(2.5);
    expect(takePosition(2.5, 120, 0.5)).toBeCloseTo(240);
  });

  it("test_aligning_one_event_puts_its_video_time_on_its_take_frame", () => {
    const offset = offsetFor(360, 4.25, 120);
    expect(offset).toBeCloseTo(1.25);
    expect(videoTime(360, 120, offset)).toBeCloseTo(4.25);
  });

  it("test_half_a_frame_is_the_videos_when_known", () => {
    expect(halfFrame(120, 30)).toBeCloseTo(1 / 60);
    expect(halfFrame(120, null)).toBeCloseTo(1 / 240);
  });
});

describe("following the clock", () => {
  it("test_paused_it_seeks_to_the_exact_time_of_the_frame", () => {
    expect(plan(clock({ position: 241 }), video(), 0, 30)).toMatchObject({ seekTo: 241 / 120, play: false });
    expect(plan(clock(), video({ currentTime: 2 }), 0, 30).seekTo).toBeNull();
  });

  it("test_paused_between_frames_it_shows_the_frame_the_page_shows", () => {
    expect(plan(clock({ position: 241.7 }), video(), 0, 30).seekTo).toBeCloseTo(241 / 120);
  });

  it("test_playing_it_leaves_drift_under_half_a_frame_alone", () => {
    const p = plan(clock({ playing: true, speed: 2 }), video({ currentTime: 2.01, paused: false }), 0, 30);
    expect(p).toEqual({ seekTo: null, play: true, rate: 2, outside: null });
  });

  it("test_playing_it_takes_up_small_drift_with_the_rate", () => {
    const ahead = plan(clock({ playing: true }), video({ currentTime: 2.05 }), 0, 30);
    expect(ahead.seekTo).toBeNull();
    expect(ahead.rate).toBeLessThan(1);
    const behind = plan(clock({ playing: true }), video({ currentTime: 1.95 }), 0, 30);
    expect(behind.rate).toBeGreaterThan(1);
  });

  it("test_playing_it_seeks_after_a_jump", () => {
    const p = plan(clock({ playing: true }), video({ currentTime: 2 + JUMP_S + 0.01 }), 0, 30);
    expect(p.seekTo).toBeCloseTo(2);
  });

  it("test_playing_it_seeks_ahead_by_what_a_seek_takes", () => {
    const p = plan(clock({ playing: true, speed: 2 }), video({ currentTime: 5 }), 0, 30, 0.1);
    expect(p.seekTo).toBeCloseTo(2.2);
  });

  it("test_it_waits_for_a_seek_in_progress", () => {
    expect(plan(clock({ position: 600 }), video({ seeking: true }), 0, 30).seekTo).toBeNull();
  });

  it("test_before_and_after_the_video_it_holds_still", () => {
    expect(plan(clock({ playing: true }), video(), -5, 30)).toMatchObject({ outside: "before", play: false, seekTo: 0 });
    expect(plan(clock({ playing: true }), video({ currentTime: 10 }), 9, 30)).toMatchObject({ outside: "after", play: false, seekTo: null });
  });

  it("test_it_keeps_the_rate_within_what_browsers_play", () => {
    expect(plan(clock({ playing: true, speed: 0.01 }), video(), 0, 30).rate).toBeGreaterThanOrEqual(0.0625);
  });
});

describe("playback listeners", () => {
  it("test_every_change_of_the_clock_is_heard", () => {
    const controller = new PlaybackController(120, 1000, 0, () => {});
    const heard = vi.fn();
    const stop = controller.listen(heard);
    controller.seek(10);
    controller.seekAndPause(20);
    controller.setSpeed(2);
    controller.setLoop({ start: 0, stop: 100 });
    expect(heard).toHaveBeenCalledTimes(4);
    stop();
    controller.seek(30);
    expect(heard).toHaveBeenCalledTimes(4);
  });
});
