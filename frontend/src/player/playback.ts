// Playback as the review and adjudication pages both run it: the pure clock (clock.ts)
// driven by animation frames, and the transport a person works (play, seek, step, speed,
// loop). The page says what to redraw on each frame through one hook; others that follow
// the clock (a reference video, video/sync.ts) listen to every change of it.

import { advance, frameOf, nextSpeed, seek, togglePlay, type Playback } from "./clock";

/** Called on every animation frame while playing, and once when playing stops by itself. */
export type OnFrame = (frame: number, playing: boolean) => void;

export class PlaybackController {
  state: Playback;
  private raf = 0;
  private lastTick = 0;
  private readonly listeners = new Set<() => void>();

  constructor(fps: number, nFrames: number, start: number, private readonly onFrame: OnFrame) {
    this.state = { position: start, playing: false, speed: 1, fps, nFrames, loop: null };
  }

  get frame(): number {
    return frameOf(this.state);
  }

  get playing(): boolean {
    return this.state.playing;
  }

  get loop(): Playback["loop"] {
    return this.state.loop;
  }

  /** Call `listener` after every change of the state (play, pause, seek, speed, loop, and
   * each animation frame while playing); returns what stops it. */
  listen(listener: () => void): () => void {
    this.listeners.add(listener);
    return () => this.listeners.delete(listener);
  }

  toggle(): void {
    this.state = togglePlay(this.state);
    this.lastTick = performance.now();
    cancelAnimationFrame(this.raf);
    if (this.state.playing) this.raf = requestAnimationFrame(this.tick);
    this.changed();
  }

  /** Show `frame` (clamped to the take); playback goes on if it was playing. */
  seek(frame: number): void {
    this.state = seek(this.state, frame);
    this.changed();
  }

  /** Show `frame` and stop there: stepping and jumping are for looking at one frame. */
  seekAndPause(frame: number): void {
    this.state = { ...seek(this.state, frame), playing: false };
    this.changed();
  }

  setSpeed(speed: number): void {
    this.state = { ...this.state, speed };
    this.changed();
  }

  /** One speed slower (-1) or faster (+1); returns the new speed. */
  nudgeSpeed(direction: -1 | 1): number {
    this.setSpeed(nextSpeed(this.state.speed, direction));
    return this.state.speed;
  }

  /** Loop `range` from its start, or stop looping (null). */
  setLoop(range: Playback["loop"]): void {
    this.state = range ? seek({ ...this.state, loop: range }, range.start) : { ...this.state, loop: null };
    this.changed();
  }

  dispose(): void {
    cancelAnimationFrame(this.raf);
    this.listeners.clear();
  }

  private changed(): void {
    for (const listener of this.listeners) listener();
  }

  private tick = (now: number): void => {
    this.state = advance(this.state, (now - this.lastTick) / 1000);
    this.lastTick = now;
    if (this.state.playing) this.raf = requestAnimationFrame(this.tick);
    // Listeners first: a video following the clock reads its own time before the page
    // spends the frame drawing, so both are read at the frame's start.
    this.changed();
    this.onFrame(this.frame, this.state.playing);
  };
}
