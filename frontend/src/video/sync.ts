// A reference video follows the page's one clock (player/playback.ts): the take's frame is
// the truth, and the video is moved to it. The video time at take frame f is
// f / fps + offset (seconds; the offset is saved per video on the server).
//
// Paused (stepping, scrubbing, seeking) the video is put on the exact time. Playing, a seek
// stalls the decoder until the next keyframe, so drift beyond half a video frame is first
// taken up by the playback rate (a few per cent faster or slower, unnoticeable), and only a
// jump (a seek on the timeline, a loop starting over, a late start) is answered by a seek.

import type { PlaybackController } from "../player/playback";

/** The clock's state the video follows. */
export interface ClockState {
  /** Fractional frame position. */
  position: number;
  playing: boolean;
  speed: number;
  fps: number;
}

/** What the video element reports. */
export interface VideoState {
  currentTime: number;
  duration: number;
  seeking: boolean;
  paused: boolean;
}

/** What to do to the video element. */
export interface Plan {
  /** Seek there (seconds), or leave the time alone. */
  seekTo: number | null;
  play: boolean;
  rate: number;
  /** The take's time lies before the video's first frame or after its last. */
  outside: "before" | "after" | null;
}

/** A drift this large while playing is a jump: seek. */
export const JUMP_S = 0.15;
/** Browsers play between these rates (Chromium: 1/16 to 16). */
const MIN_RATE = 0.0625;
const MAX_RATE = 16;
/** Share of the drift taken up per second of playing: a drift is mostly gone in 1/GAIN s. */
const GAIN = 8;

/** The video time (s) at a take position (fractional frames). */
export function videoTime(position: number, fps: number, offset: number): number {
  return position / fps + offset;
}

/** The take frame (fractional) at a video time: the inverse of videoTime. */
export function takePosition(time: number, fps: number, offset: number): number {
  return (time - offset) * fps;
}

/** The offset that puts video time `time` at take frame `frame` (align by one event). */
export function offsetFor(frame: number, time: number, fps: number): number {
  return time - frame / fps;
}

/** Half a frame of the video (of the take when the video's rate is unknown), in seconds. */
export function halfFrame(takeFps: number, videoFps: number | null): number {
  return 0.5 / (videoFps && videoFps > 0 ? videoFps : takeFps);
}

/** What the video must do to show the clock's moment. */
export function plan(clock: ClockState, video: VideoState, offset: number, videoFps: number | null, seekLead = 0): Plan {
  // Paused, the page shows the frame the position is in (a pause leaves it fractional).
  const target = videoTime(clock.playing ? clock.position : Math.floor(clock.position), clock.fps, offset);
  const duration = Number.isFinite(video.duration) ? video.duration : Infinity;
  const outside = target < 0 ? "before" : target > duration ? "after" : null;
  const clamped = Math.min(Math.max(target, 0), duration);
  const play = clock.playing && outside === null;
  const speed = clamp(clock.speed, MIN_RATE, MAX_RATE);
  if (video.seeking) return { seekTo: null, play, rate: speed, outside };
  const drift = video.currentTime - clamped; // > 0: the video is ahead
  if (!play) return { seekTo: Math.abs(drift) > 1e-3 ? clamped : null, play, rate: speed, outside };
  // The take plays on while the video seeks: aim where it will be once the seek is done.
  if (Math.abs(drift) > JUMP_S * Math.max(1, clock.speed)) return { seekTo: Math.min(clamped + seekLead * clock.speed, duration), play, rate: speed, outside };
  if (Math.abs(drift) <= halfFrame(clock.fps, videoFps)) return { seekTo: null, play, rate: speed, outside };
  const rate = clamp(clock.speed * (1 - GAIN * drift), Math.max(MIN_RATE, clock.speed / 2), Math.min(MAX_RATE, clock.speed * 2));
  return { seekTo: null, play, rate, outside };
}

function clamp(value: number, low: number, high: number): number {
  return Math.min(Math.max(value, low), high);
}

/** Keeps one video element on the clock of a PlaybackController while attached. */
export class VideoSync {
  private stop: () => void = () => {};
  private detached = false;
  /** How long a seek while playing takes here (seconds, a moving average), and when the last began. */
  private seekLead = 0;
  private seekStarted: number | null = null;
  private readonly onVideo = (e: Event) => {
    if (e.type === "seeked" && this.seekStarted !== null) {
      const took = (performance.now() - this.seekStarted) / 1000;
      this.seekLead = Math.min(0.5, this.seekLead ? 0.7 * this.seekLead + 0.3 * took : took);
      this.seekStarted = null;
    }
    this.sync();
  };

  constructor(
    private readonly video: HTMLVideoElement,
    private readonly playback: PlaybackController,
    private offset: number,
    private readonly videoFps: number | null,
    private readonly outside: (where: Plan["outside"]) => void,
  ) {
    this.stop = playback.listen(() => this.sync());
    for (const event of ["loadedmetadata", "seeked", "canplay"]) video.addEventListener(event, this.onVideo);
    this.sync();
  }

  setOffset(offset: number): void {
    this.offset = offset;
    this.sync();
  }

  /** Let the video go its own way (to find an event in it), or follow the clock again. */
  setDetached(detached: boolean): void {
    this.detached = detached;
    if (detached) this.video.pause();
    this.sync();
  }

  get isDetached(): boolean {
    return this.detached;
  }

  dispose(): void {
    this.stop();
    for (const event of ["loadedmetadata", "seeked", "canplay"]) this.video.removeEventListener(event, this.onVideo);
    this.video.pause();
  }

  sync(): void {
    const v = this.video;
    if (this.detached || v.readyState < HTMLMediaElement.HAVE_METADATA) return;
    const p = plan(this.playback.state, v, this.offset, this.videoFps, this.seekLead);
    this.outside(p.outside);
    if (v.playbackRate !== p.rate) v.playbackRate = p.rate;
    if (p.seekTo !== null) {
      this.seekStarted = p.play ? performance.now() : null;
      v.currentTime = p.seekTo;
    }
    if (p.play && v.paused) void v.play().catch(() => {});
    else if (!p.play && !v.paused) v.pause();
  }
}
