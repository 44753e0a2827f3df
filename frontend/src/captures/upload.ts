// Uploads with progress. fetch() cannot report upload progress, so this uses XHR.

import { postWithProgress } from "../api/client";
import type { Uploaded } from "../api/types";

export interface UploadItem {
  file: File;
  asf: File | null;
}

/** Files uploaded alone: motion (.bvh, .fbx) and point takes (.c3d, a Qualisys .tsv, a joint
 * .csv). The upload API takes the same list (FORMATS in segmentation/services/captures.py). */
export const SINGLE_FILE_SUFFIXES = [".bvh", ".fbx", ".c3d", ".tsv", ".csv"];
/** What the file chooser offers: the single files, and an .amc with its .asf skeleton. */
export const CHOOSER_ACCEPT = [...SINGLE_FILE_SUFFIXES, ".amc", ".asf"].join(",");

const suffixOf = (name: string) => name.slice(name.lastIndexOf(".")).toLowerCase();

/**
 * Pair dropped files into uploads: every .bvh, .fbx and point take alone, every .amc with an
 * .asf (the one sharing its subject prefix, e.g. 13_29.amc ↔ 13.asf, else the only one
 * dropped). Returns the uploads and, per file that cannot be uploaded, why.
 */
export function pairFiles(files: File[]): { items: UploadItem[]; problems: string[] } {
  const asfs = files.filter((f) => /\.asf$/i.test(f.name));
  const items: UploadItem[] = [];
  const problems: string[] = [];
  for (const file of files) {
    if (SINGLE_FILE_SUFFIXES.includes(suffixOf(file.name))) items.push({ file, asf: null });
    else if (/\.amc$/i.test(file.name)) {
      const subject = file.name.split(/[_.]/)[0];
      const asf = asfs.find((a) => a.name.replace(/\.asf$/i, "") === subject) ?? (asfs.length === 1 ? asfs[0] : null);
      if (asf) items.push({ file, asf });
      else problems.push(`${file.name}: an .amc needs its skeleton; drop the matching .asf with it.`);
    } else if (!/\.asf$/i.test(file.name)) {
      problems.push(`${file.name}: not a take Cutroom reads (.bvh, .fbx, .amc with its .asf, .c3d, .tsv or .csv).`);
    }
  }
  if (asfs.length && !files.some((f) => /\.amc$/i.test(f.name))) problems.push("An .asf alone is only a skeleton; drop it together with its .amc takes.");
  return { items, problems };
}

export function upload(item: UploadItem, project: number, onProgress: (share: number) => void): Promise<Uploaded> {
  const form = new FormData();
  form.append("file", item.file);
  if (item.asf) form.append("asf", item.asf);
  form.append("project", String(project));
  return postWithProgress("/api/captures/", form, onProgress, "The upload was interrupted (network error).");
}
