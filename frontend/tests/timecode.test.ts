import { describe, expect, it } from "vitest";
import { formatTimecode, GotoError, parseGoto } from "../src/review/timecode";

describe("formatTimecode", () => {
  it("test_it_writes_hours_minutes_seconds_and_frames_at_the_takes_rate", () => {
    expect(formatTimecode(0, 30)).toBe("00:00:00:00");
    expect(formatTimecode(30 * 3661 + 29, 30)).toBe("01:01:01:29");
    expect(formatTimecode(1234, 120)).toBe("00:00:10:034");
  });

  it("test_it_counts_a_fractional_rate_as_its_whole_frames_non_drop", () => {
    expect(formatTimecode(30, 29.97)).toBe("00:00:01:00");
  });
});

describe("parseGoto", () => {
  it("test_it_reads_a_frame_number_or_a_timecode_of_two_to_four_fields", () => {
    expect(parseGoto(" 250 ", 120, 5000)).toBe(250);
    expect(parseGoto("00:00:10:034", 120, 5000)).toBe(1234);
    expect(parseGoto("10:34", 120, 5000)).toBe(1234);
    expect(parseGoto("01:10:00", 30, 5000)).toBe(2100);
  });

  it("test_it_is_the_inverse_of_formatTimecode", () => {
    for (const frame of [0, 1, 119, 120, 4799]) expect(parseGoto(formatTimecode(frame, 120), 120, 5000)).toBe(frame);
  });

  it("test_it_names_what_is_wrong_with_bad_input", () => {
    expect(() => parseGoto("ten", 120, 5000)).toThrow(new GotoError('"ten" is neither a frame number nor a timecode (HH:MM:SS:FF).'));
    expect(() => parseGoto("00:00:01:120", 120, 5000)).toThrow("frames must be below 120 at 120 fps, not 120");
    expect(() => parseGoto("00:61:00", 30, 5000)).toThrow("seconds and minutes must be below 60");
    expect(() => parseGoto("5000", 120, 5000)).toThrow("past the take's last frame (4999, 00:00:41:079)");
  });
});
