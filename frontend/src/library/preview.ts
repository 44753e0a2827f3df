// A clip played in place: the skeleton of frames [start, stop) of a capture, looping, in
// a small box. Used by the library (a segment) and the adjudication view (a span).

import { get } from "../api/client";
import { isReady } from "../api/types";
import type { Capture, FramesResponse } from "../api/types";
import { SkeletonView, TooManyJoints } from "../player/skeletonView";
import { decodeFloat32 } from "../review/frames";
import { clear, h, toast } from "../ui/dom";

/** One answer of /frames/ carries at most this many joint positions (CUTROOM_JOINT_FRAMES_PER_REQUEST). */
const JOINT_FRAMES_PER_ANSWER = 250_000;

/** Playback step so a clip preview downloads at most `maxFrames` poses. */
export function previewStep(frames: number, maxFrames = 1500): number {
  return Math.max(1, Math.ceil(frames / maxFrames));
}

export class ClipPreview {
  private stopCurrent: () => void = () => undefined;
  private readonly captures = new Map<number, Promise<Capture>>();

  constructor(private readonly box: HTMLElement) {}

  async play(captureId: number, start: number, stop: number, caption: string, id = `${captureId}:${start}`): Promise<void> {
    this.stop();
    if (!this.captures.has(captureId)) this.captures.set(captureId, get<Capture>(`/api/captures/${captureId}/`));
    const capture = await this.captures.get(captureId)!;
    if (!isReady(capture)) return toast("This capture has no skeleton yet.", "error");
    // One answer holds the whole clip: fewer poses for a skeleton of many joints.
    const step = previewStep(stop - start, Math.min(1500, Math.floor(JOINT_FRAMES_PER_ANSWER / Math.max(capture.skeleton.joints.length, 1))));
    const frames = await get<FramesResponse>(`/api/captures/${captureId}/frames/?start=${start}&stop=${stop}&step=${step}`);
    const poses = decodeFloat32(frames.data);
    const size = frames.n_joints * 3;
    const stage = h("div", { class: "lib-stage" });
    clear(this.box, stage, h("div", { class: "muted small", "data-testid": "preview-caption" }, caption));
    let view: SkeletonView | null = null;
    try {
      view = new SkeletonView(stage, capture.skeleton);
    } catch (err) {
      const why = err instanceof TooManyJoints ? `No 3D view: ${err.message}.` : "WebGL is not available to draw the skeleton.";
      stage.append(h("p", { class: "muted" }, why));
    }
    this.box.setAttribute("data-playing", id);
    let raf = 0;
    const started = performance.now();
    const tick = (now: number) => {
      // The first animation frame can be stamped before `started`: never go negative.
      const i = Math.floor(((Math.max(now - started, 0) / 1000) * capture.fps) / step) % frames.n_frames;
      view?.setPose(poses.subarray(i * size, (i + 1) * size));
      raf = requestAnimationFrame(tick);
    };
    raf = requestAnimationFrame(tick);
    this.stopCurrent = () => {
      cancelAnimationFrame(raf);
      view?.dispose();
    };
  }

  stop(): void {
    this.stopCurrent();
    this.stopCurrent = () => undefined;
  }
}
