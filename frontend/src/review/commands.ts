// What each key command does on the review page: playback and navigation commands move
// the playhead, edit commands go to the review session. The "?" overlay is drawn from
// keymap.ts's table, so the help cannot disagree with the keys.

import type { Label, Segment } from "../api/types";
import type { PlaybackController } from "../player/playback";
import { h } from "../ui/dom";
import { labelForHotkey } from "./keys";
import { HELP, type Command } from "./keymap";
import { openPalette } from "./palette";
import type { ReviewSession } from "./session";
import { clampFrame, neighbourCut, segmentAt } from "./state";

/** What the commands act on; the page provides it. */
export interface CommandContext {
  session: ReviewSession;
  playback: PlaybackController;
  /** Labels that may be applied (the taxonomy without retired labels). */
  labels: Label[];
  /** The segment under the playhead, with its suggested label. */
  segmentHere(): Segment | undefined;
  /** Scroll the timeline so `frame` is in view. */
  reveal(frame: number): void;
  zoom(factor: number, frame: number): void;
  setSpeed(speed: number): void;
  notice(text: string): void;
}

export class Commands {
  private help: HTMLElement | null = null;

  constructor(private readonly ctx: CommandContext) {}

  run(c: Command): void {
    if (!this.edit(c)) this.view(c);
  }

  toggleHelp(): void {
    if (this.help) {
      this.help.remove();
      this.help = null;
      return;
    }
    this.help = helpOverlay(HELP, () => this.toggleHelp());
    document.body.append(this.help);
  }

  dispose(): void {
    this.help?.remove();
  }

  /** Playback, navigation and view commands. */
  private view(c: Command): void {
    const { playback, session } = this.ctx;
    const frame = playback.frame;
    switch (c.kind) {
      case "play":
        return playback.toggle();
      case "step":
      case "home":
      case "end": {
        const target = c.kind === "step" ? frame + c.frames : c.kind === "home" ? 0 : session.nFrames - 1;
        return this.goTo(clampFrame(target, session.nFrames));
      }
      case "jump": {
        const cut = neighbourCut(session.review.cuts, frame, c.direction);
        if (!cut) return;
        session.selectedCutId = cut.id;
        return this.goTo(cut.frame);
      }
      case "loop": {
        const segment = segmentAt(session.review.segments, frame);
        return playback.setLoop(playback.loop || !segment ? null : { start: segment.start, stop: segment.stop });
      }
      case "speed":
        return this.ctx.setSpeed(playback.nudgeSpeed(c.direction));
      case "zoom":
        return this.ctx.zoom(c.factor, frame);
      case "help":
        return this.toggleHelp();
      case "escape":
        if (this.help) this.toggleHelp();
        else session.selectedCutId = null;
    }
  }

  private goTo(frame: number): void {
    this.ctx.playback.seekAndPause(frame);
    this.ctx.reveal(this.ctx.playback.frame);
  }

  /** Commands that change the review; false if `c` is not one of them. */
  private edit(c: Command): boolean {
    const { session, playback } = this.ctx;
    const frame = playback.frame;
    switch (c.kind) {
      case "accept":
      case "delete":
        session.changeSelectedCut(c.kind);
        return true;
      case "insert":
        session.insertAt(frame);
        return true;
      case "label": {
        // Labels without hotkeys answer to their position in the taxonomy instead.
        const label = labelForHotkey(this.ctx.labels, c.hotkey);
        if (label) session.labelAt(frame, label.name);
        else this.ctx.notice(`No label has hotkey ${c.hotkey}.`);
        return true;
      }
      case "clearLabel":
        session.labelAt(frame, null);
        return true;
      case "palette":
        if (!session.locked()) openPalette(this.ctx.labels, (name) => session.labelAt(playback.frame, name));
        return true;
      case "acceptSuggestion": {
        const suggested = this.ctx.segmentHere()?.suggested_label;
        if (suggested) session.labelAt(frame, suggested);
        else this.ctx.notice("No suggested label for the segment under the playhead.");
        return true;
      }
      case "undo":
        session.undo();
        return true;
      case "redo":
        session.redo();
        return true;
      default:
        return false;
    }
  }
}

/** The keyboard help: one row per key, closed by a click anywhere or by "?"/Escape. */
export function helpOverlay(rows: [string, string][], close: () => void, extraClass = ""): HTMLElement {
  return h(
    "div",
    { class: `modal-backdrop help ${extraClass}`.trim(), "data-testid": "help", onclick: close },
    h("div", { class: "modal" }, h("h2", {}, "Keyboard"), h("table", { class: "keys" }, ...rows.map(([keys, what]) => h("tr", {}, h("th", {}, h("kbd", {}, keys)), h("td", {}, what))))),
  );
}
