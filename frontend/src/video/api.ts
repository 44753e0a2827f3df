// The reference-video API of a capture (docs/api.md, "Reference videos").

import { api, get, patch, postWithProgress } from "../api/client";
import type { components } from "../api/schema";

export type Video = components["schemas"]["Video"];
export type VideoList = components["schemas"]["VideoList"];

const base = (captureId: number) => `/api/captures/${captureId}/videos/`;

export const listVideos = (captureId: number) => get<VideoList>(base(captureId));

export const saveOffset = (captureId: number, videoId: number, offset: number) =>
  patch<Video>(`${base(captureId)}${videoId}/`, { offset_s: offset });

export const removeVideo = (captureId: number, videoId: number) => api<null>("DELETE", `${base(captureId)}${videoId}/`);

/** Upload one file with progress (0..1); the promise fails with the server's message. */
export function uploadVideo(captureId: number, file: File, onProgress: (share: number) => void): Promise<Video & { duplicate: boolean }> {
  const form = new FormData();
  form.append("file", file);
  return postWithProgress(base(captureId), form, onProgress, `${file.name}: the upload was interrupted (network error).`);
}

/** A refusal made before sending: a file larger than the server takes. */
export function tooLarge(file: File, maxMb: number): string | null {
  if (file.size <= maxMb * 1024 * 1024) return null;
  return `${file.name} is ${(file.size / 2 ** 20).toFixed(1)} MB; the limit for a video is ${maxMb} MB.`;
}
