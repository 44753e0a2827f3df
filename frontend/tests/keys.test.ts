import { describe, expect, it } from "vitest";
import { labelForHotkey, pageCommand, type PageKey } from "../src/review/keys";

function press(key: string, target: object | null = { tagName: "BODY" }): PageKey & { prevented: boolean } {
  const e = {
    key, shiftKey: false, ctrlKey: false, metaKey: false, altKey: false, target: target as EventTarget, prevented: false,
    preventDefault() { e.prevented = true; },
  };
  return e;
}

const noDialog = () => false;

describe("pageCommand", () => {
  it("test_it_gives_the_command_and_prevents_the_browser_default", () => {
    const e = press(" ");
    expect(pageCommand(e, noDialog)).toEqual({ kind: "play" });
    expect(e.prevented).toBe(true);
  });

  it("test_it_leaves_keys_that_are_no_command_to_the_browser", () => {
    const e = press("q");
    expect(pageCommand(e, noDialog)).toBeNull();
    expect(e.prevented).toBe(false);
  });

  it("test_it_ignores_keys_typed_into_a_field", () => {
    for (const tagName of ["INPUT", "TEXTAREA", "SELECT"]) {
      const e = press("a", { tagName });
      expect(pageCommand(e, noDialog)).toBeNull();
      expect(e.prevented).toBe(false);
    }
    expect(pageCommand(press("a", { tagName: "DIV", isContentEditable: true }), noDialog)).toBeNull();
  });

  it("test_it_ignores_keys_while_a_dialog_is_open", () => {
    const e = press("a");
    expect(pageCommand(e, () => true)).toBeNull();
    expect(e.prevented).toBe(false);
  });
});

describe("labelForHotkey", () => {
  const walk = { name: "walk", hotkey: "2" };
  const run = { name: "run", hotkey: null };
  const jump = { name: "jump", hotkey: "" };

  it("test_it_finds_the_label_by_its_hotkey_when_labels_have_hotkeys", () => {
    expect(labelForHotkey([run, walk], "2")).toBe(walk);
    expect(labelForHotkey([run, walk], "1")).toBeUndefined();
  });

  it("test_it_counts_positions_when_no_label_has_a_hotkey", () => {
    expect(labelForHotkey([run, jump], "1")).toBe(run);
    expect(labelForHotkey([run, jump], "2")).toBe(jump);
    expect(labelForHotkey([run, jump], "3")).toBeUndefined();
  });
});
