import { describe, expect, it } from "vitest";
import { inviteNote } from "../src/team/page";

describe("team page", () => {
  it("test_it_promises_the_same_answer_only_to_those_who_get_it", () => {
    expect(inviteNote(false)).toContain("the same whether or not the name exists");
    expect(inviteNote(true)).not.toContain("the same whether or not");
    expect(inviteNote(true)).toContain("told when no account has the name");
  });
});
