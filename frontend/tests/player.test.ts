import { describe, expect, it } from "vitest";
import { advance, frameOf, nextSpeed, seek, togglePlay, type Playback } from "../src/player/clock";
import { seenPoint, sideOf } from "../src/player/skeletonView";

const playing = (over: Partial<Playback> = {}): Playback => ({ position: 0, playing: true, speed: 1, fps: 120, nFrames: 1000, loop: null, ...over });

describe("playback clock", () => {
  it("test_it_advances_by_fps_times_speed_frames_per_second", () => {
    expect(frameOf(advance(playing(), 0.1))).toBe(12);
    expect(frameOf(advance(playing({ speed: 0.5 }), 0.1))).toBe(6);
  });

  it("test_it_does_not_leap_after_a_long_pause_in_a_background_tab", () => {
    expect(frameOf(advance(playing(), 30))).toBe(30);
  });

  it("test_it_stops_on_the_last_frame", () => {
    const p = advance(playing({ position: 995 }), 0.25);
    expect(p).toMatchObject({ position: 999, playing: false });
  });

  it("test_it_wraps_inside_the_loop_range", () => {
    const p = advance(playing({ position: 290, loop: { start: 200, stop: 300 } }), 0.1);
    expect(frameOf(p)).toBe(202);
    expect(frameOf(advance(playing({ position: 10, loop: { start: 200, stop: 300 } }), 0.01))).toBeGreaterThanOrEqual(200);
  });

  it("test_it_restarts_from_the_top_when_played_at_the_end", () => {
    expect(togglePlay({ ...playing(), playing: false, position: 999 })).toMatchObject({ playing: true, position: 0 });
    expect(togglePlay(playing({ position: 500 }))).toMatchObject({ playing: false, position: 500 });
  });

  it("test_it_seeks_to_whole_frames_inside_the_take", () => {
    expect(seek(playing(), 12.6).position).toBe(13);
    expect(seek(playing(), -4).position).toBe(0);
    expect(seek(playing(), 5000).position).toBe(999);
  });

  it("test_it_steps_speed_through_the_preset_list", () => {
    expect(nextSpeed(1, 1)).toBe(1.5);
    expect(nextSpeed(1, -1)).toBe(0.5);
    expect(nextSpeed(4, 1)).toBe(4);
    expect(nextSpeed(0.1, -1)).toBe(0.1);
  });
});

describe("sideOf", () => {
  it("test_it_colours_cmu_bvh_and_mixamo_joint_names_by_side", () => {
    for (const n of ["lfemur", "lhumerus", "lhipjoint", "LeftUpLeg", "LHipJoint", "mixamorig:LeftArm", "hand.L"]) expect(sideOf(n), n).toBe("left");
    for (const n of ["rfemur", "rtibia", "RightForeArm", "RHipJoint", "mixamorig:RightHand"]) expect(sideOf(n), n).toBe("right");
    for (const n of ["root", "lowerback", "LowerBack", "Root", "head", "thorax", "Hips", "lowerneck", "Spine"]) expect(sideOf(n), n).toBe("centre");
  });
});

describe("seenPoint", () => {
  it("test_it_follows_the_first_point_seen_when_the_root_is_a_gap", () => {
    const pose = new Float32Array([Number.NaN, Number.NaN, Number.NaN, 1, 2, 3, 4, 5, 6]);
    expect(seenPoint(pose)?.toArray()).toEqual([1, 2, 3]);
  });

  it("test_it_finds_nothing_in_a_frame_where_no_point_is_seen", () => {
    expect(seenPoint(new Float32Array([Number.NaN, 0, 0, 0, Number.NaN, 0]))).toBeNull();
  });
});

describe("sideOf for point takes", () => {
  it("test_it_knows_the_side_of_kinect_joints_and_plug_in_gait_markers", () => {
    expect(["elbow_left", "ElbowLeft", "Bastian:LELB"].map(sideOf)).toEqual(["left", "left", "left"]);
    expect(["knee_right", "HandRight", "RKNE"].map(sideOf)).toEqual(["right", "right", "right"]);
    expect(["hip_center", "spine", "C7"].map(sideOf)).toEqual(["centre", "centre", "centre"]);
  });
});
