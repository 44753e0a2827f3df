// What each key command does on the review page: playback and navigation commands move
// the playhead, edit commands go to the review session. The "?" overlay is drawn from
// keymap.ts's table, so the help cannot disagree with the keys.

import type { Label, Segment } from "../api/types";
import type { PlaybackController } from "../player/playback";
import { h } from "../ui/dom";
import { promptLine } from "../ui/prompt";
import { labelForHotkey } from "./keys";
import { HELP, type Command } from "./keymap";
import { openPalette } from "./palette";
import type { ReviewSession } from "./session";
import { clampFrame, nearestDeleted, neighbourCut, neighbourPending, neighbourUnlabelled, segmentAt } from "./state";
import { formatTimecode, GotoError, parseGoto } from "./timecode";

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
  notice(text: string, error?: boolean): void;
  /** Redraw after a command that finished later (the "go to" prompt). */
  refresh(): void;
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
      case "jump":
      case "pending": {
        const cut = (c.kind === "jump" ? neighbourCut : neighbourPending)(session.review.cuts, frame, c.direction);
        if (!cut) return c.kind === "pending" ? this.ctx.notice(`No pending candidate ${c.direction > 0 ? "after" : "before"} frame ${frame}.`) : undefined;
        session.selectedCutId = cut.id;
        return this.goTo(cut.frame);
      }
      case "unlabelled": {
        const segment = neighbourUnlabelled(session.review.segments, frame, c.direction);
        if (!segment) return this.ctx.notice(`No unlabelled segment ${c.direction > 0 ? "after" : "before"} frame ${frame}.`);
        return this.goTo(segment.start);
      }
      case "goto":
        return void this.askGoto();
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

  /** Ask for a frame or a timecode and go there; a bad answer is named, the playhead stays. */
  private async askGoto(): Promise<void> {
    const { session, playback } = this.ctx;
    const fps = playback.state.fps;
    const last = `${session.nFrames - 1} (${formatTimecode(session.nFrames - 1, fps)})`;
    const text = await promptLine("Go to", `A frame number (0 to ${last}) or a timecode HH:MM:SS:FF at ${fps} fps.`, "Go", formatTimecode(playback.frame, fps));
    if (text === null) return;
    try {
      this.goTo(parseGoto(text, fps, session.nFrames));
    } catch (err) {
      if (!(err instanceof GotoError)) throw err;
      this.ctx.notice(err.message, true);
    }
    this.ctx.refresh();
  }

  private goTo(frame: number): void {
    this.ctx.playback.seekAndPause(frame);
    this.ctx.reveal(this.ctx.playback.frame);
  }

  /** Move the selected cut by `frames` (a move on the server, as a drag is) and follow it. */
  private nudge(frames: number): void {
    const { session } = this.ctx;
    const cut = session.selectedCut();
    if (!cut) return this.ctx.notice("Select a cut first: click it, or jump to it with Shift+←/→ or N.");
    if (session.perform({ kind: "move", cutId: cut.id, frame: cut.frame + frames })) this.goTo(cut.frame + frames);
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
      case "nudge":
        this.nudge(c.frames);
        return true;
      case "restore": {
        const cut = nearestDeleted(session.review.cuts, frame);
        if (!cut) this.ctx.notice("No deleted candidate to restore.");
        else if (session.perform({ kind: "fate", cutId: cut.id, fate: "pending" })) {
          session.selectedCutId = cut.id;
          this.goTo(cut.frame);
        }
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
