import { describe, expect, it } from "vitest";
import { commandFor, HELP, type KeyInput } from "../src/review/keymap";

const key = (k: string, mods: Partial<KeyInput> = {}): KeyInput => ({ key: k, shiftKey: false, ctrlKey: false, metaKey: false, altKey: false, ...mods });

describe("commandFor", () => {
  it("test_it_maps_the_documented_editing_keys", () => {
    expect(commandFor(key(" "))).toEqual({ kind: "play" });
    expect(commandFor(key("ArrowLeft"))).toEqual({ kind: "step", frames: -1 });
    expect(commandFor(key("ArrowRight"))).toEqual({ kind: "step", frames: 1 });
    expect(commandFor(key("ArrowLeft", { shiftKey: true }))).toEqual({ kind: "jump", direction: -1 });
    expect(commandFor(key("ArrowRight", { shiftKey: true }))).toEqual({ kind: "jump", direction: 1 });
    expect(commandFor(key("a"))).toEqual({ kind: "accept" });
    expect(commandFor(key("d"))).toEqual({ kind: "delete" });
    expect(commandFor(key("i"))).toEqual({ kind: "insert" });
    expect(commandFor(key("?", { shiftKey: true }))).toEqual({ kind: "help" });
  });

  it("test_it_maps_digits_one_to_nine_to_label_hotkeys", () => {
    for (const d of "123456789") expect(commandFor(key(d))).toEqual({ kind: "label", hotkey: d });
    expect(commandFor(key("0"))).toEqual({ kind: "clearLabel" });
  });

  it("test_it_undoes_with_z_and_redoes_with_shift_z_or_ctrl_shift_z", () => {
    expect(commandFor(key("z"))).toEqual({ kind: "undo" });
    expect(commandFor(key("Z", { shiftKey: true }))).toEqual({ kind: "redo" });
    expect(commandFor(key("z", { ctrlKey: true }))).toEqual({ kind: "undo" });
    expect(commandFor(key("Z", { ctrlKey: true, shiftKey: true }))).toEqual({ kind: "redo" });
    expect(commandFor(key("z", { metaKey: true, shiftKey: true }))).toEqual({ kind: "redo" });
  });

  it("test_it_treats_capital_letters_like_lower_case", () => {
    expect(commandFor(key("A", { shiftKey: true }))).toEqual({ kind: "accept" });
    expect(commandFor(key("D"))).toEqual({ kind: "delete" });
  });

  it("test_it_leaves_browser_shortcuts_alone", () => {
    expect(commandFor(key("a", { ctrlKey: true }))).toBeNull();
    expect(commandFor(key("d", { altKey: true }))).toBeNull();
    expect(commandFor(key("q"))).toBeNull();
  });

  it("test_it_nudges_with_alt_arrows_a_frame_and_with_alt_shift_arrows_a_step", () => {
    expect(commandFor(key("ArrowLeft", { altKey: true }))).toEqual({ kind: "nudge", frames: -1 });
    expect(commandFor(key("ArrowRight", { altKey: true }))).toEqual({ kind: "nudge", frames: 1 });
    expect(commandFor(key("ArrowRight", { altKey: true, shiftKey: true }))).toEqual({ kind: "nudge", frames: 10 });
    expect(commandFor(key("ArrowLeft", { altKey: true, ctrlKey: true }))).toBeNull();
  });

  it("test_it_maps_the_navigation_restore_and_goto_keys", () => {
    expect(commandFor(key("n"))).toEqual({ kind: "pending", direction: 1 });
    expect(commandFor(key("N", { shiftKey: true }))).toEqual({ kind: "pending", direction: -1 });
    expect(commandFor(key("u"))).toEqual({ kind: "unlabelled", direction: 1 });
    expect(commandFor(key("U", { shiftKey: true }))).toEqual({ kind: "unlabelled", direction: -1 });
    expect(commandFor(key("r"))).toEqual({ kind: "restore" });
    expect(commandFor(key("g"))).toEqual({ kind: "goto" });
  });

  it("test_it_documents_every_required_key_in_the_help", () => {
    const text = HELP.map(([k]) => k).join(" | ");
    for (const k of ["Space", "← / →", "Shift + ← / →", "A", "D", "I", "1 – 9", "Z", "Shift+Z", "?", "Alt + ← / →", "Alt + Shift + ← / →", "N / Shift+N", "U / Shift+U", "R", "G"]) expect(text).toContain(k);
  });
});
