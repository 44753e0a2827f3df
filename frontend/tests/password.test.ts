import { describe, expect, it } from "vitest";
import { passwordProblem } from "../src/ui/password";

describe("passwordProblem", () => {
  it("test_it_lets_a_filled_in_confirmed_new_password_through", () => {
    expect(passwordProblem("old-one", "a-new-one", "a-new-one")).toBeNull();
  });

  it("test_it_asks_for_the_fields_left_empty", () => {
    expect(passwordProblem("", "a-new-one", "a-new-one")).toBe("Type your current password.");
    expect(passwordProblem("old-one", "", "")).toBe("Type a new password.");
  });

  it("test_it_catches_a_mistyped_confirmation_and_an_unchanged_password", () => {
    expect(passwordProblem("old-one", "a-new-one", "a-new-on")).toMatch(/differ/);
    expect(passwordProblem("same", "same", "same")).toMatch(/same as the current/);
  });
});
