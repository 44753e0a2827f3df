// The review page's stage: a capture's poses loading in the background, and the 3D player
// that shows the pose of the frame under the playhead, with its frame read-outs.

import { get } from "../api/client";
import type { Me, ReadyCapture, Signal, SignalResponse } from "../api/types";
import { MAX_JOINTS, SkeletonView, TooManyJoints } from "../player/skeletonView";
import { h } from "../ui/dom";
import { decodeFloat32, FrameStore, loadFrames } from "./frames";
import type { Elements } from "./layout";
import { formatTimecode } from "./timecode";
import { formatTime } from "./timescale";

/** A capture's poses loading in the background, with a hook for each chunk that lands. */
export class FrameFeed {
  readonly store: FrameStore;
  readonly abort = new AbortController();
  readonly started = performance.now();
  readonly done: Promise<void>;
  /** Settles when the first chunk has landed (the first pose can be drawn), or loading ended. */
  readonly first: Promise<void>;
  /** Lets the poses after the first chunk load (see signalsWait); aborting does too. */
  resume: () => void = () => {};
  onChunk: () => void = () => {};

  constructor(capture: ReadyCapture, maxJoints: number, holdAfterFirst: boolean) {
    // Poses the player will not draw are not fetched (nor memory set aside for them).
    const drawable = jointCount(capture) <= maxJoints;
    this.store = new FrameStore(capture.n_frames, drawable ? jointCount(capture) : 0);
    let landed = () => {};
    this.first = new Promise<void>((resolve) => (landed = resolve));
    const onChunk = () => {
      landed();
      this.onChunk();
    };
    const gate = new Promise<void>((resolve) => (this.resume = resolve));
    if (!holdAfterFirst) this.resume();
    this.abort.signal.addEventListener("abort", () => this.resume());
    this.done = drawable ? loadFrames(capture.id, this.store, frameFromUrl(capture.n_frames), onChunk, this.abort.signal, gate) : Promise.resolve();
    void this.done.finally(landed);
  }
}

/**
 * The previous request order, `?signals=after-poses`: the full-resolution signals asked for
 * once every pose has loaded. Kept so benchmarks/review_long_take.py can time both orders
 * in the same run.
 */
export function signalsAfterPoses(search = location.search): boolean {
  return new URLSearchParams(search).get("signals") === "after-poses";
}

/**
 * When the full-resolution signals are asked for: once the first pose is on screen. The
 * other poses wait until the lanes are drawn (FrameFeed.resume): an hour-long take's poses
 * take seconds to load, its signals a fraction of one, and on a small server the signals'
 * request would otherwise queue behind pose chunks.
 */
export function signalsWait(frames: FrameFeed): Promise<void> {
  return signalsAfterPoses() ? frames.done : frames.first;
}

/** `/signal/?encoding=float32`: each signal's values as base64 little-endian float32. */
type PackedSignalResponse = Omit<SignalResponse, "signals"> & { signals: (Omit<Signal, "values"> & { data: string })[] };

/**
 * The first paint uses signals decimated to a few thousand points; once the first pose is
 * on screen (signalsWait), they are fetched at full frame resolution so zooming in shows
 * every frame. Null when they already are, or the page was left meanwhile.
 */
export async function fullSignals(capture: ReadyCapture, shown: Signal[], abort: AbortSignal): Promise<Signal[] | null> {
  if (abort.aborted || !shown.some((sig) => sig.step > 1)) return null;
  // Every frame's value as base64 float32: 5.3 bytes a value instead of ~9 of JSON, and no numbers to parse.
  const full = await get<PackedSignalResponse>(`/api/captures/${capture.id}/signal/?max_points=${capture.n_frames}&encoding=float32`).catch(() => null);
  if (!full || abort.aborted) return null;
  return full.signals.map(({ data, ...sig }) => ({ ...sig, values: Array.from(decodeFloat32(data)) }));
}

export function jointCount(capture: ReadyCapture): number {
  return Math.max(capture.n_joints ?? 0, capture.skeleton?.joints.length ?? 0);
}

export function maxJoints(me: Me): number {
  return me.limits?.max_joints ?? MAX_JOINTS;
}

/** The frame asked for by `?frame=N` (the library links a segment's start this way), else 0. */
export function frameFromUrl(nFrames: number, search = location.search): number {
  const frame = Number(new URLSearchParams(search).get("frame"));
  return Number.isInteger(frame) && frame > 0 ? Math.min(frame, Math.max(nFrames - 1, 0)) : 0;
}

/** The 3D player and the read-outs above it, fed by a FrameFeed. */
export class Stage {
  private readonly player: SkeletonView | null;
  private shownFrame = -1;
  private floorSet = false;

  constructor(private readonly el: Elements, private readonly capture: ReadyCapture, me: Me, private readonly feed: FrameFeed) {
    this.player = this.makePlayer(maxJoints(me));
  }

  /** The camera follows the root, or not; false when there is no player. */
  toggleFollow(): boolean {
    if (!this.player) return false;
    this.player.follow = !this.player.follow;
    return this.player.follow;
  }

  show(frame: number): void {
    const c = this.capture;
    this.el.hudFrame.textContent = `Frame ${frame} / ${c.n_frames - 1}`;
    // Timecode as the studio writes it; the clock time is the read-out's tooltip.
    this.el.hudTime.textContent = `${formatTimecode(frame, c.fps)} / ${formatTimecode(c.n_frames - 1, c.fps)} · ${c.fps} fps`;
    this.el.hudTime.title = `${formatTime(frame, c.fps)} / ${formatTime(c.n_frames - 1, c.fps)}`;
    const store = this.feed.store;
    if (frame === this.shownFrame || !this.player) return;
    const shown = store.has(frame) ? frame : store.nearestLoaded(frame);
    if (shown === null) return;
    this.player.setPose(store.pose(shown));
    this.shownFrame = shown === frame ? frame : -1;
    // Milliseconds from navigation to the first pose on screen: the "opens in" figure.
    this.el.viewport.dataset.firstPoseMs ??= String(Math.round(performance.now()));
  }

  /** A chunk of poses landed: the loading bar moves on, the frame shown is drawn again. */
  loaded(frame: number): void {
    const s = this.feed.store;
    const share = s.loadedFrames / s.nFrames;
    this.el.loadingBar.style.width = `${(share * 100).toFixed(1)}%`;
    this.el.loading.toggleAttribute("hidden", share >= 1 && !s.error);
    if (s.error) this.el.loading.replaceChildren(h("span", { class: "error-text" }, `Could not load frames: ${s.error}`));
    if (share >= 1) this.el.loading.dataset.done = `${Math.round(performance.now() - this.feed.started)}`;
    const floor = s.floorLevel();
    if (floor !== null && !this.floorSet) {
      this.player?.setFloor(floor);
      this.floorSet = true;
    }
    this.shownFrame = -1;
    this.show(frame);
  }

  dispose(): void {
    this.feed.abort.abort();
    this.player?.dispose();
  }

  private makePlayer(limit: number): SkeletonView | null {
    const joints = jointCount(this.capture);
    if (joints > limit) {
      const text = `No 3D view: this capture has ${new TooManyJoints(joints, limit).message}. The timeline still works.`;
      this.el.viewport.append(h("div", { class: "no-webgl", "data-testid": "too-many-joints" }, text));
      this.el.loading.hidden = true;
      return null;
    }
    try {
      return new SkeletonView(this.el.viewport, this.capture.skeleton!, limit);
    } catch (err) {
      this.el.viewport.append(h("div", { class: "no-webgl" }, `3D view unavailable (${err instanceof Error ? err.message : "no WebGL"}); the timeline still works.`));
      return null;
    }
  }
}
