// The clip library: filter and sort labelled segments, play one in place, find clips
// that move like it, open it in its capture, export one BVH or the whole query as a zip.

import { get } from "../api/client";
import type { Me, Page, Project } from "../api/types";
import type { Member } from "../queue/api";
import { clear, clip, formatDuration, h, toast } from "../ui/dom";
import { annotationExportMenu } from "./annotationExport";
import { clipsWhat, downloadWithProgress } from "./download";
import { topbar } from "./nav";
import { GlbPreview } from "./gltfPreview";
import { ClipPreview } from "./preview";
import type { LibrarySegment } from "./types";

export interface LibraryFilters {
  project: string;
  label: string;
  annotator: string;
  min_duration: string;
  max_duration: string;
  min_agreement: string;
  gold: string;
  /** A segment attribute as name:value (quality:good, needs cleanup:true). */
  attribute: string;
  ordering: string;
  page: number;
}

const KEYS = ["project", "label", "annotator", "min_duration", "max_duration", "min_agreement", "gold", "attribute", "ordering"] as const;
export const ORDERINGS: [string, string][] = [["recent", "Newest"], ["-duration", "Longest"], ["duration", "Shortest"], ["-agreement", "Most agreed"], ["agreement", "Least agreed"], ["label", "Label"], ["capture", "Capture"]];

export function libraryFiltersFrom(search: string): LibraryFilters {
  const q = new URLSearchParams(search);
  const f = Object.fromEntries(KEYS.map((k) => [k, q.get(k) ?? ""])) as Omit<LibraryFilters, "page">;
  return { ...f, page: Math.max(Number(q.get("page")) || 1, 1) };
}

/** The API query string of the filters (empty values left out), without "?". */
export function libraryQuery(f: LibraryFilters, withPage = true): string {
  const q = new URLSearchParams();
  for (const k of KEYS) if (f[k]) q.set(k, f[k]);
  if (withPage && f.page > 1) q.set("page", String(f.page));
  return q.toString();
}

/** A segment's attribute values as one muted line (none: nothing). */
export function attributeText(s: { attributes?: Record<string, unknown> }): HTMLElement | null {
  const values = Object.entries(s.attributes ?? {});
  if (!values.length) return null;
  const text = values.map(([name, value]) => (value === true ? name : value === false ? `not ${name}` : `${name}: ${String(value)}`)).join(" · ");
  return h("div", { class: "muted lib-attributes", "data-testid": "segment-attributes" }, text);
}

/** "1 segment", "7 segments", or "10,000+ segments" when the server stopped counting. */
export function segmentCount(count: number, capped: boolean): string {
  return `${count.toLocaleString("en-US")}${capped ? "+" : ""} segment${count === 1 && !capped ? "" : "s"}`;
}

/** The top bar, its dashboard and team links for the project filtered on, else the first
 * project the user reviews or administers. */
function navFor(projects: Project[], filtered: number): HTMLElement {
  const project = projects.find((p) => p.id === filtered) ?? projects.find((p) => p.role !== "annotator");
  return topbar([["Captures", "/"], ["Library", null]], project && project.role !== "annotator" ? project.id : undefined, project?.role);
}

/** The annotators the filter offers: the members of the projects the user reviews or
 * administers; an annotator, who sees only their own segments (and gold), is offered
 * themself. */
async function annotatorsOf(projects: Project[], me: string): Promise<string[]> {
  const managed = projects.filter((p) => p.role !== "annotator");
  const lists = await Promise.all(managed.map((p) => get<Member[]>(`/api/projects/${p.id}/members/`).catch(() => [] as Member[])));
  const names = new Set([me, ...lists.flat().map((m) => m.username)]);
  return [...names].sort();
}

/** A segment's export in one format: a link (save it with the browser as well), downloaded
 * with progress when clicked, since Blender writes FBX and glTF on request. */
function exportLink(s: LibrarySegment, fmt: string, text: string, testId: string): HTMLElement {
  const href = `/api/segments/${s.id}/export.${fmt}`;
  const link = h("a", { class: "btn", "data-testid": testId, href, download: "", title: fmt === "glb" ? "glTF binary" : `${text} file` }, text);
  link.addEventListener("click", (e) => {
    e.preventDefault();
    void downloadWithProgress(href, `${s.label} ${s.start}–${s.stop} as ${text}`, `segment-${s.id}.${fmt}`);
  });
  return link;
}

const pct = (v: number | null) => (v === null ? "—" : `${Math.round(v * 100)} %`);

export async function renderLibrary(root: HTMLElement): Promise<() => void> {
  const [projectsRaw, me] = await Promise.all([get<Project[] | Page<Project>>("/api/projects/"), get<Me>("/api/me/")]);
  const projects = Array.isArray(projectsRaw) ? projectsRaw : projectsRaw.results;
  const labelNames = [...new Set(projects.flatMap((p) => p.labels.map((l) => l.name)))].sort();
  const annotatorNames = await annotatorsOf(projects, me.username);
  let filters = libraryFiltersFrom(location.search);
  const rows = h("tbody", { "data-testid": "segment-rows" });
  const pager = h("div", { class: "pager" });
  const exportZip = h("a", { class: "btn", "data-testid": "export-zip", download: "" }, "Export these as zip");
  exportZip.addEventListener("click", (e) => {
    e.preventDefault();
    // Only the clips the chosen format writes are counted: the server says how many.
    const format = zipFormat.selectedOptions[0]?.text ?? zipFormat.value;
    void downloadWithProgress(zipHref(), `clips as ${format}`, `segments-${zipFormat.value}.zip`, (r) => clipsWhat(r.headers.get("X-Clip-Count"), format));
  });
  const zipFormat = h(
    "select",
    { class: "select", "data-testid": "export-format", "aria-label": "export format", title: "Clip format in the zip" },
    h("option", { value: "bvh" }, "BVH"),
    h("option", { value: "fbx" }, "FBX"),
    h("option", { value: "glb" }, "glTF"),
    h("option", { value: "c3d", title: "segments of point takes (markers, tracked joints)" }, "C3D (points)"),
    h("option", { value: "csv", title: "segments of point takes (markers, tracked joints)" }, "CSV (points)"),
  ) as HTMLSelectElement;
  const zipHref = () => `/api/segments/export.zip?${libraryQuery(filters, false)}&file_format=${zipFormat.value}`;
  zipFormat.addEventListener("change", () => exportZip.setAttribute("href", zipHref()));
  const preview = h("aside", { class: "lib-preview", "data-testid": "preview" }, h("p", { class: "muted" }, "Play a segment to preview it here."));
  const player = new ClipPreview(preview);
  const glbPlayer = new GlbPreview(preview);

  const field = (key: (typeof KEYS)[number], el: HTMLInputElement | HTMLSelectElement) => {
    el.value = filters[key];
    // An unknown or empty value shows the first choice rather than a blank select.
    if (el instanceof HTMLSelectElement && el.selectedIndex < 0) el.selectedIndex = 0;
    el.setAttribute("data-testid", `lib-${key}`);
    el.setAttribute("aria-label", key.replace("_", " "));
    el.addEventListener("change", () => apply({ ...filters, [key]: el.value.trim(), page: 1 }));
    return el;
  };
  const options = (pairs: [string, string][]) => pairs.map(([v, t]) => h("option", { value: v }, t));
  const controls = h(
    "div",
    { class: "filters lib-filters" },
    field("project", h("select", { class: "select" }, ...options([["", "All projects"], ...projects.map((p) => [String(p.id), p.name] as [string, string])]))),
    field("label", h("select", { class: "select" }, ...options([["", "Any label"], ...labelNames.map((l) => [l, l] as [string, string])]))),
    field("annotator", h("select", { class: "select" }, ...options([["", "Any annotator"], ...annotatorNames.map((n) => [n, n] as [string, string])]))),
    field("min_duration", h("input", { class: "input num-input", type: "number", step: "0.1", min: "0", placeholder: "min s" })),
    field("max_duration", h("input", { class: "input num-input", type: "number", step: "0.1", min: "0", placeholder: "max s" })),
    field("min_agreement", h("input", { class: "input num-input", type: "number", step: "0.05", min: "0", max: "1", placeholder: "min agreement" })),
    field("gold", h("select", { class: "select" }, ...options([["", "Gold where made"], ["true", "Gold only"], ["false", "Annotators' versions"]]))),
    field("attribute", h("input", { class: "input", placeholder: "attribute name:value", title: "A segment attribute, e.g. quality:good or needs cleanup:true" })),
    field("ordering", h("select", { class: "select" }, ...options(ORDERINGS))),
    zipFormat,
    exportZip,
    annotationExportMenu((f) => `/api/segments/annotations.${f}?${libraryQuery(filters, false)}`, "these segments' labels", "Download these segments' labels for ELAN, Label Studio or a spreadsheet", "export-annotations"),
  );

  // The list shows agreement; "Similar" shows motion distance in the same column.
  const metricHead = h("th", { "data-testid": "metric-head" }, "Agreement");
  clear(
    root,
    h(
      "div",
      { class: "list-page" },
      navFor(projects, Number(filters.project)),
      h(
        "main",
        { class: "list-main lib-main" },
        controls,
        h(
          "div",
          { class: "lib-layout" },
          h("div", { class: "lib-table" }, h("table", { class: "captures" }, h("thead", {}, h("tr", {}, ...["Label", "Capture", "Frames", "Duration", "Annotator"].map((t) => h("th", {}, t)), metricHead, h("th", {}))), rows), pager),
          preview,
        ),
      ),
    ),
  );

  // A segment of a point take (markers, tracked joints) downloads as C3D or CSV; one of joint
  // rotations as BVH, FBX or glTF.
  function exportButtons(s: LibrarySegment): HTMLElement[] {
    if (!s.export_formats.includes("bvh")) {
      return [exportLink(s, "c3d", "C3D", `c3d-${s.id}`), exportLink(s, "csv", "CSV", `csv-${s.id}`)];
    }
    return [
      exportLink(s, "bvh", "BVH", `bvh-${s.id}`),
      exportLink(s, "fbx", "FBX", `fbx-${s.id}`),
      exportLink(s, "glb", "glTF", `glb-${s.id}`),
      h("button", { class: "btn", "data-testid": `play-glb-${s.id}`, title: "Play the glTF export as three.js loads it", onclick: () => void playGlb(s) }, "▶ glTF"),
    ];
  }

  function row(s: LibrarySegment): HTMLElement {
    return h(
      "tr",
      { "data-testid": `segment-${s.id}` },
      h("td", {}, h("span", { class: "label-dot", style: `background:${s.color}` }), clip(s.label), s.gold ? h("span", { class: "badge badge-ready gold-badge" }, "gold") : null, attributeText(s)),
      h("td", {}, clip(s.capture.name, { href: `/captures/${s.capture.id}/?frame=${s.start}` })),
      h("td", { class: "num" }, `${s.start}–${s.stop}`),
      h("td", { class: "num" }, formatDuration(s.duration)),
      h("td", {}, s.annotator ? clip(s.annotator.username) : "—"),
      h("td", { class: "num" }, s.distance !== undefined ? `d ${s.distance.toFixed(2)}` : pct(s.agreement)),
      h(
        "td",
        { class: "lib-actions" },
        h("button", { class: "btn", "data-testid": `play-${s.id}`, onclick: () => void play(s) }, "▶ Play"),
        h("button", { class: "btn", "data-testid": `similar-${s.id}`, onclick: () => void similar(s) }, "Similar"),
        ...exportButtons(s),
      ),
    );
  }

  async function load(): Promise<void> {
    const query = libraryQuery(filters);
    exportZip.setAttribute("href", zipHref());
    const data = await get<Page<LibrarySegment> & { count_capped?: boolean }>(`/api/segments/?${query}`).catch((err: Error) => {
      clear(rows, h("tr", {}, h("td", { colspan: 7, class: "error-text", "data-testid": "lib-error" }, err.message)));
      return null;
    });
    if (!data) return;
    metricHead.textContent = "Agreement";
    clear(rows, ...data.results.map(row));
    if (!data.results.length) rows.append(h("tr", {}, h("td", { colspan: 7, class: "muted empty" }, "No segments match. Segments appear here when reviews are submitted.")));
    clear(
      pager,
      h("span", { class: "muted", "data-testid": "segment-count" }, segmentCount(data.count, data.count_capped ?? false)),
      data.previous ? h("button", { class: "btn", onclick: () => apply({ ...filters, page: filters.page - 1 }) }, "← Previous") : null,
      data.next ? h("button", { class: "btn", onclick: () => apply({ ...filters, page: filters.page + 1 }) }, "Next →") : null,
    );
  }

  async function similar(s: LibrarySegment): Promise<void> {
    try {
      const body = await get<{ results: LibrarySegment[] }>(`/api/segments/${s.id}/similar/?k=10`);
      metricHead.textContent = "Distance";
      const n = body.results.length;
      clear(pager, h("span", { class: "muted", "data-testid": "segment-count" }, `${n} similar clip${n === 1 ? "" : "s"}`));
      clear(rows, h("tr", {}, h("td", { colspan: 7, class: "lib-similar-head" }, `Clips that move like ${s.label} ${s.start}–${s.stop} of ${s.capture.name} `, h("button", { class: "btn btn-ghost", onclick: () => void load() }, "× back to the list"))), ...body.results.map(row));
    } catch (err) {
      toast((err as Error).message, "error");
    }
  }

  async function playGlb(s: LibrarySegment): Promise<void> {
    player.stop();
    try {
      await glbPlayer.play(`/api/segments/${s.id}/export.glb`, `${s.label} · ${s.capture.name} · frames ${s.start}–${s.stop}`, `glb:${s.id}`);
    } catch (err) {
      toast(`glTF export of ${s.label} ${s.start}–${s.stop}: ${(err as Error).message}`, "error");
    }
  }

  async function play(s: LibrarySegment): Promise<void> {
    glbPlayer.stop();
    await player.play(s.capture.id, s.start, s.stop, `${s.label} · ${s.capture.name} · frames ${s.start}–${s.stop}`, String(s.id));
  }

  function apply(next: LibraryFilters): void {
    filters = next;
    const query = libraryQuery(filters);
    history.replaceState(null, "", `/library/${query ? `?${query}` : ""}`);
    void load();
  }

  await load();
  return () => {
    player.stop();
    glbPlayer.stop();
  };
}
