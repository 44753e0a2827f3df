// The keyboard as the review and adjudication pages share it: which presses are the
// page's commands, and which label a digit key names. (The key table itself is keymap.ts.)

import { commandFor, isTypingTarget, type Command, type KeyInput } from "./keymap";

export interface PageKey extends KeyInput {
  target: EventTarget | null;
  preventDefault(): void;
}

/** Whether a dialog other than the "?" overlay is open: it has the keyboard then. */
function dialogOpen(): boolean {
  return document.querySelector(".modal-backdrop:not(.help)") !== null;
}

/**
 * The page command a key press asks for, or null when the press is not the page's: the
 * person is typing in a field, or a dialog is open. A press that is a command has its
 * default action (scrolling, the browser's own shortcut) prevented.
 */
export function pageCommand(e: PageKey, isDialogOpen: () => boolean = dialogOpen, attributeKeys = ""): Command | null {
  if (isTypingTarget(e.target) || isDialogOpen()) return null;
  const command = commandFor(e, attributeKeys);
  if (command) e.preventDefault();
  return command;
}

/**
 * The label a digit key names: the label with that hotkey or, when no label has a hotkey,
 * the label at that position ("1" is the first); undefined when none.
 */
export function labelForHotkey<L extends { hotkey?: string | null }>(labels: L[], hotkey: string): L | undefined {
  if (labels.some((l) => l.hotkey)) return labels.find((l) => l.hotkey === hotkey);
  return labels[Number(hotkey) - 1];
}
