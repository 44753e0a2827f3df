// Exports downloaded with progress: an FBX or glTF clip is written by Blender on request and
// a zip of many clips streams for as long as they take, so a plain download link left a
// person looking at nothing. An export that runs longer than a second shows what it is, how
// much has arrived and for how long, then saves the file under the server's name.

import { errorText } from "../api/client";
import { h, toast } from "../ui/dom";

/** How long an export runs before its progress shows. */
export const PROGRESS_AFTER_MS = 1000;

/** "2.4 MB" from a byte count. */
export function formatBytes(bytes: number): string {
  if (bytes < 1024) return `${bytes} B`;
  if (bytes < 1024 * 1024) return `${(bytes / 1024).toFixed(1)} kB`;
  return `${(bytes / 1024 / 1024).toFixed(1)} MB`;
}

/** The file name of a Content-Disposition header, else `fallback`. */
export function attachmentName(header: string | null, fallback: string): string {
  const match = /filename="([^"]+)"/.exec(header ?? "");
  return match ? match[1] : fallback;
}

let box: HTMLElement | null = null;

function progressBox(): HTMLElement {
  if (!box || !box.isConnected) {
    box = h("div", { class: "export-progress-box", "aria-live": "polite" });
    document.body.append(box);
  }
  return box;
}

/** "3 clips as glTF" from the zip's X-Clip-Count header (the clips the server writes, not
 * every segment that matched), or null without one. */
export function clipsWhat(header: string | null, format: string): string | null {
  if (header === null || !/^\d+$/.test(header)) return null;
  const n = Number(header);
  return `${n} clip${n === 1 ? "" : "s"} as ${format}`;
}

/** Download `url`, showing its progress once it has run for a second (`what` says what it
 * is, until `answered` tells it better from the response's headers). */
export async function downloadWithProgress(url: string, what: string, fallbackName: string, answered?: (response: Response) => string | null): Promise<void> {
  const started = performance.now();
  const bar = h("div", { class: "export-progress-bar" });
  const text = h("span", {}, `Exporting ${what}…`);
  const line = h("div", { class: "export-progress", "data-testid": "export-progress", role: "status" }, text, h("div", { class: "export-progress-track" }, bar));
  let received = 0;
  const show = () => {
    const seconds = Math.round((performance.now() - started) / 1000);
    text.textContent = `Exporting ${what}… ${formatBytes(received)} received · ${seconds} s`;
    if (!line.isConnected) progressBox().append(line);
  };
  const timer = window.setInterval(show, PROGRESS_AFTER_MS);
  try {
    const response = await fetch(url, { credentials: "same-origin" });
    what = (response.ok && answered?.(response)) || what;
    if (!response.ok) {
      const body = (response.headers.get("content-type") ?? "").includes("json") ? await response.json() : await response.text();
      throw new Error(errorText(response.status, body));
    }
    const parts: BlobPart[] = [];
    const reader = response.body!.getReader();
    for (;;) {
      const { done, value } = await reader.read();
      if (done) break;
      parts.push(value);
      received += value.length;
    }
    save(new Blob(parts, { type: response.headers.get("content-type") ?? "application/octet-stream" }), attachmentName(response.headers.get("content-disposition"), fallbackName));
    if (line.isConnected) toast(`Exported ${what}: ${formatBytes(received)} in ${((performance.now() - started) / 1000).toFixed(1)} s.`);
  } catch (err) {
    toast(`Export of ${what} failed: ${(err as Error).message}`, "error");
  } finally {
    window.clearInterval(timer);
    line.remove();
  }
}

function save(blob: Blob, name: string): void {
  const href = URL.createObjectURL(blob);
  const link = h("a", { href, download: name, hidden: true });
  document.body.append(link);
  link.click();
  link.remove();
  window.setTimeout(() => URL.revokeObjectURL(href), 60_000);
}
