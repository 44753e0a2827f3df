// The reference-video dock of the review and adjudication pages: the capture's videos
// played in sync with the take (sync.ts), and, for reviewers and admins, adding videos
// through a file dialog, nudging the offset by one or ten video frames, aligning by one
// event seen in both, and removing a video. Offsets are saved on the server at once.

import type { PlaybackController } from "../player/playback";
import { clear, h, toast } from "../ui/dom";
import { listVideos, removeVideo, saveOffset, tooLarge, uploadVideo, type Video, type VideoList } from "./api";
import { offsetFor, takePosition, VideoSync, type Plan } from "./sync";
import "./video.css";

export interface DockOptions {
  captureId: number;
  /** The take's frame rate and length. */
  fps: number;
  nFrames: number;
  playback: PlaybackController;
  /** Float over the 3D stage (review page) rather than sit in a column (adjudication). */
  floating?: boolean;
}

const ACCEPT = "video/mp4,video/webm,.mp4,.m4v,.webm";

export class VideoDock {
  readonly root: HTMLElement;
  private list: VideoList | null = null;
  private current: Video | null = null;
  private sync: VideoSync | null = null;
  private readonly video: HTMLVideoElement;
  private readonly outside: HTMLElement;
  private readonly body: HTMLElement;
  private readonly status: HTMLElement;
  private readonly input: HTMLInputElement;
  private shownOutside: Plan["outside"] = null;
  private saves: Promise<unknown> = Promise.resolve();
  private collapsed = false;

  constructor(container: HTMLElement, private readonly opts: DockOptions) {
    this.video = h("video", { class: "video-player", "data-testid": "reference-video", muted: true, playsinline: true, preload: "auto", disablepictureinpicture: true });
    this.video.muted = true; // the attribute alone does not mute a video made by script
    this.outside = h("div", { class: "video-outside", "data-testid": "video-outside", hidden: true });
    this.body = h("div", { class: "video-body" });
    this.status = h("div", { class: "video-status", "data-testid": "video-status", role: "status" });
    this.input = h("input", { type: "file", accept: ACCEPT, multiple: true, hidden: true, "data-testid": "video-file" });
    this.input.addEventListener("change", () => void this.uploadChosen());
    this.root = h("section", { class: `video-dock${opts.floating ? " floating" : ""}`, "data-testid": "video-dock", hidden: true });
    container.append(this.root);
    void this.load();
  }

  dispose(): void {
    this.sync?.dispose();
    this.video.removeAttribute("src");
    this.root.remove();
  }

  /** Read the capture's videos; keep showing `select` (or the one shown) when there. */
  private async load(select?: number): Promise<void> {
    try {
      this.list = await listVideos(this.opts.captureId);
    } catch (err) {
      this.note(`Reference videos could not be loaded: ${(err as Error).message}`, true);
      return;
    }
    const videos = this.list.videos;
    const keep = select ?? this.current?.id;
    this.show(videos.find((v) => v.id === keep) ?? videos[0] ?? null);
  }

  private show(video: Video | null): void {
    if (video?.id !== this.current?.id || !video) this.play(video);
    this.current = video;
    this.render();
  }

  /** Put `video` in the player and on the clock. */
  private play(video: Video | null): void {
    this.sync?.dispose();
    this.sync = null;
    this.video.controls = false;
    if (!video) {
      this.video.removeAttribute("src");
      return;
    }
    this.video.src = video.url;
    this.sync = new VideoSync(this.video, this.opts.playback, video.offset_s, video.fps ?? null, (where) => this.showOutside(where));
  }

  private render(): void {
    const list = this.list;
    if (!list) return;
    const manage = list.may_manage;
    this.root.hidden = !manage && list.videos.length === 0;
    const header = h(
      "header",
      { class: "video-head" },
      h("b", {}, "Reference video"),
      list.videos.length > 1 ? this.chooser(list.videos) : null,
      h("span", { class: "spacer" }),
      manage ? this.button("video-add", "Add video…", "Upload an MP4 (H.264) or WebM video of this take", () => this.input.click()) : null,
      this.button("video-collapse", this.collapsed ? "Show" : "Hide", "Show or hide the video", () => {
        this.collapsed = !this.collapsed;
        this.render();
      }),
    );
    clear(this.body);
    const v = this.current;
    if (v && !this.collapsed) {
      this.body.append(h("div", { class: "video-frame" }, this.video, this.outside), this.facts(v), this.offsetRow(v, manage));
      if (manage) this.body.append(this.alignRow(v), h("div", { class: "video-actions" }, this.button("video-remove", "Remove video", `Remove ${v.name} from this capture`, () => void this.remove(v))));
    } else if (!v && !this.collapsed) {
      this.body.append(h("p", { class: "muted small" }, `No reference video yet. Add an MP4 (H.264) or WebM file recorded with this take (at most ${list.max_mb} MB).`));
    }
    // The element stays in the document while hidden so that it keeps its place in the file.
    if (this.collapsed || !v) this.body.append(h("div", { hidden: true }, this.video));
    clear(this.root, header, this.body, this.status, this.input);
  }

  private chooser(videos: Video[]): HTMLElement {
    const select = h("select", { class: "select", "data-testid": "video-choice", title: "Which video to show" },
      ...videos.map((v) => h("option", { value: v.id, selected: v.id === this.current?.id }, v.name)));
    select.addEventListener("change", () => {
      select.blur();
      this.show(videos.find((v) => v.id === Number(select.value)) ?? null);
    });
    return select;
  }

  private facts(v: Video): HTMLElement {
    const parts = v.codec
      ? [v.codec.toUpperCase(), v.fps ? `${round(v.fps, 3)} fps` : null, v.duration ? `${v.duration.toFixed(2)} s` : null, v.width ? `${v.width}×${v.height}` : null]
      : [v.container.toUpperCase(), "duration and frame rate unknown (the server has no ffprobe)"];
    return h("div", { class: "video-facts muted small", "data-testid": "video-facts", title: v.name }, v.name, " · ", parts.filter(Boolean).join(" · "));
  }

  /** The offset read-out, and for those who may change it: nudges of 1 or 10 video frames and an exact value. */
  private offsetRow(v: Video, manage: boolean): HTMLElement {
    const shown = h("b", { "data-testid": "video-offset" }, `${v.offset_s >= 0 ? "+" : ""}${v.offset_s.toFixed(3)} s`);
    const row = h("div", { class: "video-offset" }, h("span", { title: "The video's time at take time t is t + offset" }, "Offset "), shown);
    if (!manage) return row;
    const step = 1 / (v.fps || this.opts.fps);
    const unit = v.fps ? "video frame" : "take frame";
    const nudge = (n: number) => this.button(`video-nudge-${n > 0 ? "plus" : "minus"}-${Math.abs(n)}`, `${n > 0 ? "+" : "−"}${Math.abs(n)}f`, `Show the video ${Math.abs(n)} ${unit}${Math.abs(n) > 1 ? "s" : ""} ${n > 0 ? "further on" : "further back"} at each take frame (offset ${n > 0 ? "+" : "−"}${(step * Math.abs(n)).toFixed(3)} s)`, () => this.setOffset(v, v.offset_s + n * step));
    const exact = h("input", { type: "number", step: "0.001", class: "input video-offset-input", value: v.offset_s.toFixed(3), "data-testid": "video-offset-input", "aria-label": "offset in seconds", title: "Offset in seconds; Enter saves" });
    exact.addEventListener("change", () => {
      const value = Number(exact.value);
      if (exact.value.trim() === "" || !Number.isFinite(value)) return this.note(`Offset: “${exact.value}” is not a number of seconds.`, true);
      exact.blur();
      this.setOffset(v, value);
    });
    row.append(nudge(-10), nudge(-1), nudge(1), nudge(10), exact, h("span", { class: "muted small" }, "s"));
    return row;
  }

  /** Align by one event seen in both (a clap, a foot strike): its take frame and its video time. */
  private alignRow(v: Video): HTMLElement {
    const frame = h("input", { type: "number", min: 0, max: this.opts.nFrames - 1, step: 1, class: "input", "data-testid": "align-frame", "aria-label": "take frame of the event", placeholder: "frame" });
    const time = h("input", { type: "number", min: 0, step: "0.001", class: "input", "data-testid": "align-time", "aria-label": "video time of the event (s)", placeholder: "s" });
    const find = this.button("align-find", "Find in video", "Play and scrub the video on its own to find the event", () => {
      const sync = this.sync;
      if (!sync) return;
      if (!sync.isDetached) {
        sync.setDetached(true);
        this.video.controls = true;
        find.textContent = "Use video time";
        this.note("The video runs on its own now: find the event, then press “Use video time”.");
      } else {
        time.value = this.video.currentTime.toFixed(3);
        this.video.controls = false;
        sync.setDetached(false);
        find.textContent = "Find in video";
        this.note("");
      }
    });
    const align = this.button("align", "Align", "Set the offset so that the video time falls on the take frame", () => {
      const f = Number(frame.value);
      const t = Number(time.value);
      if (frame.value === "" || !Number.isInteger(f) || f < 0 || f >= this.opts.nFrames) return this.note(`Align: the take frame must be a whole number from 0 to ${this.opts.nFrames - 1}, got “${frame.value}”.`, true);
      if (time.value === "" || !Number.isFinite(t) || t < 0) return this.note(`Align: the video time must be seconds from 0, got “${time.value}”.`, true);
      this.setOffset(v, offsetFor(f, t, this.opts.fps));
    });
    return h(
      "div",
      { class: "video-align", "data-testid": "video-align" },
      h("span", { class: "muted small" }, "Align one event:"),
      h("label", { class: "small" }, "take frame ", frame),
      this.button("align-playhead", "Playhead", "Use the frame under the playhead", () => (frame.value = String(this.opts.playback.frame))),
      h("label", { class: "small" }, "video time ", time),
      find,
      align,
    );
  }

  /** Show `offset` at once and save it; saves go one after the other, the last one wins. */
  private setOffset(v: Video, offset: number): void {
    const value = Math.round(offset * 1e6) / 1e6;
    this.current = { ...v, offset_s: value };
    if (this.list) this.list = { ...this.list, videos: this.list.videos.map((w) => (w.id === v.id ? this.current! : w)) };
    this.sync?.setOffset(value);
    this.render();
    const { captureId } = this.opts;
    this.saves = this.saves.then(async () => {
      try {
        const saved = await saveOffset(captureId, v.id, value);
        if (this.current?.offset_s === value) this.root.dataset.savedOffset = String(saved.offset_s);
        this.note(`Offset saved: ${saved.offset_s.toFixed(3)} s.`);
      } catch (err) {
        this.note(`Offset not saved: ${(err as Error).message}`, true);
        void this.load(v.id);
      }
    });
  }

  private async uploadChosen(): Promise<void> {
    const files = [...(this.input.files ?? [])];
    this.input.value = "";
    const max = this.list?.max_mb ?? Infinity;
    let last: number | undefined;
    for (const file of files) {
      const refused = tooLarge(file, max);
      if (refused) {
        this.note(refused, true);
        continue;
      }
      try {
        const video = await uploadVideo(this.opts.captureId, file, (share) => this.note(`Uploading ${file.name}: ${Math.round(share * 100)} %`));
        last = video.id;
        this.note(video.duplicate ? `${file.name} was already here: it is ${video.name}.` : `${file.name} added.`);
      } catch (err) {
        this.note((err as Error).message, true);
      }
    }
    if (last !== undefined) await this.load(last);
  }

  private async remove(v: Video): Promise<void> {
    if (!confirm(`Remove ${v.name} from this capture? Its file is deleted.`)) return;
    try {
      await removeVideo(this.opts.captureId, v.id);
      this.note(`${v.name} removed.`);
      this.current = null;
      await this.load();
    } catch (err) {
      this.note((err as Error).message, true);
    }
  }

  private showOutside(where: Plan["outside"]): void {
    if (where === this.shownOutside) return;
    this.shownOutside = where;
    const v = this.current;
    this.outside.hidden = where === null || !v;
    if (!where || !v) return;
    const first = Math.ceil(takePosition(0, this.opts.fps, v.offset_s));
    this.outside.textContent = where === "before" ? `The video starts at take frame ${first}` : "The video has ended";
  }

  /** A line under the dock (and a toast for errors): what happened, in words. */
  private note(text: string, error = false): void {
    this.status.textContent = text;
    this.status.classList.toggle("error-text", error);
    if (error) toast(text, "error");
  }

  private button(id: string, text: string, title: string, action: () => void): HTMLButtonElement {
    return h("button", {
      class: "btn btn-small", "data-testid": id, title,
      onclick: (e: Event) => {
        // Keys belong to the page (Space plays), not to the last button clicked.
        (e.currentTarget as HTMLElement).blur();
        action();
      },
    }, text);
  }
}

function round(value: number, digits: number): number {
  const scale = 10 ** digits;
  return Math.round(value * scale) / scale;
}
