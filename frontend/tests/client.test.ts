import { describe, expect, it } from "vitest";
import { retryDelay } from "../src/api/client";

describe("retryDelay", () => {
  it("test_it_asks_again_after_a_busy_servers_retry_after", () => {
    expect(retryDelay("GET", 429, "5", 0)).toBe(5000);
    expect(retryDelay("PATCH", 429, "2", 1)).toBe(2000);
  });

  it("test_it_asks_again_for_a_read_that_got_no_answer_but_never_for_a_write", () => {
    expect(retryDelay("GET", 502, "5", 0)).toBe(5000);
    expect(retryDelay("POST", 502, "5", 0)).toBeNull();
    expect(retryDelay("PATCH", 503, "5", 0)).toBeNull();
  });

  it("test_it_gives_up_after_three_tries_and_waits_at_most_ten_seconds", () => {
    expect(retryDelay("GET", 429, "5", 3)).toBeNull();
    expect(retryDelay("GET", 429, "600", 0)).toBe(10000);
  });

  it("test_it_passes_on_other_answers_and_unreadable_retry_afters", () => {
    expect(retryDelay("GET", 200, "5", 0)).toBeNull();
    expect(retryDelay("GET", 404, "5", 0)).toBeNull();
    expect(retryDelay("GET", 429, null, 0)).toBeNull();
    expect(retryDelay("GET", 429, "Wed, 21 Oct 2026 07:28:00 GMT", 0)).toBeNull();
  });
});
