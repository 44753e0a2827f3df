// Keyboard-first editing: one table maps keys to commands, and the "?" overlay is drawn
// from the same table so the help can never disagree with the behaviour.

export type Command =
  | { kind: "play" }
  | { kind: "step"; frames: number }
  | { kind: "jump"; direction: -1 | 1 }
  | { kind: "nudge"; frames: number }
  | { kind: "pending"; direction: -1 | 1 }
  | { kind: "unlabelled"; direction: -1 | 1 }
  | { kind: "restore" }
  | { kind: "goto" }
  | { kind: "accept" }
  | { kind: "delete" }
  | { kind: "insert" }
  | { kind: "label"; hotkey: string }
  | { kind: "clearLabel" }
  | { kind: "acceptSuggestion" }
  | { kind: "palette" }
  | { kind: "undo" }
  | { kind: "redo" }
  | { kind: "loop" }
  | { kind: "speed"; direction: -1 | 1 }
  | { kind: "zoom"; factor: number }
  | { kind: "home" }
  | { kind: "end" }
  | { kind: "help" }
  | { kind: "escape" }
  | { kind: "comment"; on: "playhead" | "segment" }
  | { kind: "commentJump"; direction: -1 | 1 }
  | { kind: "attribute"; hotkey: string; back: boolean };

/** Letters no other command uses: a segment attribute's hotkey is one of them (the server
 * holds the same list, segmentation/models/attributes.py). */
export const ATTRIBUTE_KEYS = "befhjkopqtvwxy";

export interface KeyInput {
  key: string;
  shiftKey: boolean;
  ctrlKey: boolean;
  metaKey: boolean;
  altKey: boolean;
}

/** The command of a key press; `attributeKeys`: the hotkeys of the project's segment
 * attributes (any other letter of ATTRIBUTE_KEYS is left to the browser). */
export function commandFor(e: KeyInput, attributeKeys = ""): Command | null {
  const mod = e.ctrlKey || e.metaKey;
  const key = e.key.length === 1 ? e.key.toLowerCase() : e.key;
  if (mod && key === "z") return e.shiftKey ? { kind: "redo" } : { kind: "undo" };
  if (mod && key === "y") return { kind: "redo" };
  if (mod) return null;
  if (e.altKey) return nudgeFor(key, e.shiftKey);
  if (key === "ArrowLeft") return e.shiftKey ? { kind: "jump", direction: -1 } : { kind: "step", frames: -1 };
  if (key === "ArrowRight") return e.shiftKey ? { kind: "jump", direction: 1 } : { kind: "step", frames: 1 };
  if (/^[1-9]$/.test(key)) return { kind: "label", hotkey: key };
  if (key === "0" || key === "Backspace") return { kind: "clearLabel" };
  if (key.length === 1 && ATTRIBUTE_KEYS.includes(key) && attributeKeys.includes(key)) return { kind: "attribute", hotkey: key, back: e.shiftKey };
  return SIMPLE[e.shiftKey ? `shift+${key}` : key] ?? SIMPLE[key] ?? null;
}

/** Frames a cut moves with Alt+Shift+←/→: the same step as "," and ".". */
export const NUDGE_STEP = 10;

/** Alt+←/→ nudge the selected cut by a frame, Alt+Shift+←/→ by a step; other Alt keys are the browser's. */
function nudgeFor(key: string, shift: boolean): Command | null {
  const sign = key === "ArrowLeft" ? -1 : key === "ArrowRight" ? 1 : 0;
  return sign ? { kind: "nudge", frames: sign * (shift ? NUDGE_STEP : 1) } : null;
}

const SIMPLE: Record<string, Command> = {
  " ": { kind: "play" },
  a: { kind: "accept" },
  d: { kind: "delete" },
  Delete: { kind: "delete" },
  i: { kind: "insert" },
  s: { kind: "acceptSuggestion" },
  "/": { kind: "palette" },
  z: { kind: "undo" },
  "shift+z": { kind: "redo" },
  l: { kind: "loop" },
  "[": { kind: "speed", direction: -1 },
  "]": { kind: "speed", direction: 1 },
  "=": { kind: "zoom", factor: 1 / 1.5 },
  "+": { kind: "zoom", factor: 1 / 1.5 },
  "-": { kind: "zoom", factor: 1.5 },
  ",": { kind: "step", frames: -NUDGE_STEP },
  ".": { kind: "step", frames: NUDGE_STEP },
  n: { kind: "pending", direction: 1 },
  "shift+n": { kind: "pending", direction: -1 },
  u: { kind: "unlabelled", direction: 1 },
  "shift+u": { kind: "unlabelled", direction: -1 },
  r: { kind: "restore" },
  g: { kind: "goto" },
  Home: { kind: "home" },
  End: { kind: "end" },
  "?": { kind: "help" },
  Escape: { kind: "escape" },
  c: { kind: "comment", on: "playhead" },
  "shift+c": { kind: "comment", on: "segment" },
  m: { kind: "commentJump", direction: 1 },
  "shift+m": { kind: "commentJump", direction: -1 },
};

/** Rows of the "?" overlay: keys, then what they do. */
export const HELP: [string, string][] = [
  ["Space", "play / pause"],
  ["← / →", "previous / next frame"],
  [", / .", "10 frames back / forward"],
  ["Shift + ← / →", "jump to previous / next cut"],
  ["Home / End", "first / last frame"],
  ["N / Shift+N", "next / previous pending candidate (selects it)"],
  ["U / Shift+U", "next / previous unlabelled segment"],
  ["G", "go to a frame or a timecode (HH:MM:SS:FF), typed"],
  ["Alt + ← / →", "nudge the selected cut one frame earlier / later"],
  ["Alt + Shift + ← / →", `nudge the selected cut ${NUDGE_STEP} frames`],
  ["A", "accept the selected candidate"],
  ["D or Delete", "delete the selected cut"],
  ["I", "insert a cut at the playhead"],
  ["R", "restore the deleted candidate nearest the playhead"],
  ["1 – 9", "label the segment under the playhead"],
  ["0 or Backspace", "clear that segment's label"],
  ["S", "accept that segment's suggested label"],
  ["/", "label palette: type to filter, Enter applies"],
  ["Z or Ctrl+Z", "undo"],
  ["Shift+Z or Ctrl+Shift+Z", "redo"],
  ["L", "loop the segment under the playhead (again: stop)"],
  ["Shift + drag the ruler", "loop any range (Shift+click clears)"],
  ["Alt + drag, middle drag", "pan the timeline"],
  ["[ / ]", "slower / faster"],
  ["+ / −, wheel", "zoom the timeline (Shift+wheel pans)"],
  ["Click the ruler or a lane", "seek there (never edits)"],
  ["Click a cut's handle", "select it (A accepts) · drag the handle to move the cut"],
  ["Double-click a lane", "insert a cut there"],
  ["Click a grey × under the ruler", "restore that deleted candidate"],
  ["Click the overview strip", "seek anywhere in the take; the working window follows"],
  ["C", "comment at the playhead (on the selected cut when one is selected)"],
  ["Shift+C", "comment on the segment under the playhead (it follows the segment's start)"],
  ["M / Shift+M", "next / previous comment (the playhead moves to its frame)"],
  ["An attribute's letter (Shift: backwards)", "set that attribute of the segment under the playhead: next option, yes/no, or type a note"],
  ["?", "show / hide this help"],
];

/** Keys typed into a form field belong to the field, not to the editor. */
export function isTypingTarget(target: EventTarget | null): boolean {
  const el = target as HTMLElement | null;
  if (!el || !el.tagName) return false;
  return el.isContentEditable || ["INPUT", "TEXTAREA", "SELECT"].includes(el.tagName);
}
