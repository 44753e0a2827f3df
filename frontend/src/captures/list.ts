// The capture list: filter by project, status and name; drop files anywhere to upload
// them (with progress); rows still being processed refresh themselves.

import "../queue/queue.css";
import { get, post } from "../api/client";
import type { CaptureSummary, Me, Page, Project, Role } from "../api/types";
import { clear, clip, formatDuration, h, toast } from "../ui/dom";
import { accountLinks, appLinks } from "../ui/appnav";
import { assignmentBar, teamCell } from "./assign";
import { invitationsBox } from "./invitations";
import { newProjectButton } from "./newProject";
import { navigate } from "../router";
import { CHOOSER_ACCEPT, pairFiles, upload, type UploadItem } from "./upload";

const STATUSES = ["", "queued", "processing", "ready", "failed"];

export interface Filters {
  project: string;
  status: string;
  search: string;
  page: number;
}

export function filtersFrom(search: string): Filters {
  const q = new URLSearchParams(search);
  return { project: q.get("project") ?? "", status: q.get("status") ?? "", search: q.get("search") ?? "", page: Math.max(Number(q.get("page")) || 1, 1) };
}

export function queryOf(f: Filters): string {
  const q = new URLSearchParams();
  if (f.project) q.set("project", f.project);
  if (f.status) q.set("status", f.status);
  if (f.search) q.set("search", f.search);
  if (f.page > 1) q.set("page", String(f.page));
  const text = q.toString();
  return text ? `?${text}` : "";
}

export async function renderCaptureList(root: HTMLElement): Promise<() => void> {
  const [me, projectsRaw] = await Promise.all([get<Me>("/api/me/"), get<Project[] | Page<Project>>("/api/projects/")]);
  const projects = Array.isArray(projectsRaw) ? projectsRaw : projectsRaw.results;
  let filters = filtersFrom(location.search);
  let timer = 0;
  let searchDelay = 0;
  let latest = 0; // only the newest list request may draw (answers can arrive out of order)
  let mounted = true;
  const rows = h("tbody", { "data-testid": "capture-rows" });
  const pager = h("div", { class: "pager" });
  const uploads = h("div", { class: "uploads", "data-testid": "uploads" });
  const fileInput = h("input", { type: "file", multiple: true, accept: CHOOSER_ACCEPT, hidden: true });
  const projectName = new Map(projects.map((p) => [p.id, p.name]));
  const projectRole = new Map(projects.map((p) => [p.id, p.role]));

  const select = (name: keyof Filters, options: [string, string][]) => {
    const el = h("select", { class: "select", "data-testid": `filter-${name}`, "aria-label": name }, ...options.map(([v, t]) => h("option", { value: v, selected: String(filters[name]) === v }, t)));
    el.addEventListener("change", () => apply({ ...filters, [name]: el.value, page: 1 }));
    return el;
  };
  const search = h("input", { class: "input", type: "search", placeholder: "Search captures…", value: filters.search, "data-testid": "filter-search" });
  search.addEventListener("input", () => {
    clearTimeout(searchDelay);
    searchDelay = window.setTimeout(() => apply({ ...filters, search: search.value.trim(), page: 1 }), 250);
  });

  // With "All projects" selected and several projects, nothing says where a file should
  // go: ask instead of guessing.
  const uploadProject = () => Number(filters.project) || (projects.length === 1 ? projects[0].id : undefined);
  const startUploads = (files: File[]) => {
    const project = uploadProject();
    if (!projects.length) return toast("Create a project (New project, above) or accept an invitation to one before uploading.", "error");
    if (!project) return toast("Choose the project to upload to in the project filter first.", "error");
    const { items, problems } = pairFiles(files);
    problems.forEach((p) => toast(p, "error"));
    for (const item of items) {
      const bar = h("div", { class: "bar" });
      const state = h("span", { class: "state" }, "waiting");
      uploads.append(h("div", { class: "upload" }, h("span", { class: "name" }, item.file.name), h("div", { class: "progress" }, bar), state));
      // One upload at a time: the first file is ready sooner than if all shared the line.
      uploadChain = uploadChain.then(() => sendOne(item, project, bar, state));
    }
  };
  let uploadChain = Promise.resolve();
  const sendOne = async (item: UploadItem, project: number, bar: HTMLElement, state: HTMLElement) => {
    const row = state.parentElement!;
    try {
      const capture = await upload(item, project, (share) => {
        bar.style.width = `${share * 100}%`;
        state.textContent = `${Math.round(share * 100)} %`;
      });
      state.textContent = capture.duplicate ? "already uploaded" : "uploaded";
      row.classList.add("done");
      setTimeout(() => row.remove(), 4000);
      if (mounted) void load();
    } catch (err) {
      state.textContent = err instanceof Error ? err.message : String(err);
      row.classList.add("failed");
    }
  };
  fileInput.addEventListener("change", () => {
    startUploads([...(fileInput.files ?? [])]);
    fileInput.value = "";
  });

  const nav = h("span", { class: "nav-links" });
  const drawNav = () => {
    const project = projects.find((p) => String(p.id) === filters.project);
    clear(nav, ...appLinks(project?.id ?? (projects.length === 1 ? projects[0].id : null), project?.role ?? (projects.length === 1 ? projects[0].role : null)));
  };
  const selection = new Set<number>();
  // With one project there is nothing to pick: its captures are the ones ticked.
  const assignProject = () => Number(filters.project) || (projects.length === 1 ? projects[0].id : null);
  const assignBar = assignmentBar(projects, assignProject, selection, () => void load());
  drawNav();
  const dropzone = h("div", { class: "dropzone", "data-testid": "dropzone" }, h("b", {}, "Drop .bvh, .fbx, .amc with its .asf, or point takes (.c3d, .tsv, .csv) here"), h("span", {}, " or "), h("button", { class: "btn btn-primary", onclick: () => fileInput.click() }, "Choose files"));
  const page = h(
    "div",
    { class: "list-page" },
    h("header", { class: "topbar" }, h("a", { class: "brand", href: "/" }, "Cutroom"), h("nav", { class: "crumbs" }, h("strong", {}, "Captures")), h("span", { class: "spacer" }), nav, ...accountLinks(me.username)),
    h(
      "main",
      { class: "list-main" },
      invitationsBox(() => location.reload()),
      h(
        "div",
        { class: "filters" },
        select("project", [["", "All projects"], ...projects.map((p) => [String(p.id), p.name] as [string, string])]),
        select("status", STATUSES.map((s) => [s, s ? s : "Any status"] as [string, string])),
        search,
        h("span", { class: "spacer" }),
        newProjectButton(),
      ),
      dropzone,
      fileInput,
      uploads,
      assignBar.el,
      h(
        "table",
        { class: "captures" },
        h("thead", {}, h("tr", {}, h("th", {}, ""), ...["Name", "Project", "Status", "Frames", "Duration", "fps", "Joints", "Cuts", "Team", "Uploaded"].map((t) => h("th", {}, t)))),
        rows,
      ),
      pager,
    ),
  );
  clear(root, page);

  const onDrag = (e: DragEvent) => {
    e.preventDefault();
    dropzone.classList.toggle("over", e.type === "dragover");
  };
  const onDrop = (e: DragEvent) => {
    e.preventDefault();
    dropzone.classList.remove("over");
    startUploads([...(e.dataTransfer?.files ?? [])]);
  };
  document.addEventListener("dragover", onDrag);
  document.addEventListener("dragleave", onDrag);
  document.addEventListener("drop", onDrop);

  async function load(): Promise<void> {
    clearTimeout(timer);
    const request = ++latest;
    const q = new URLSearchParams(queryOf(filters).slice(1));
    const data = await get<Page<CaptureSummary>>(`/api/captures/?${q}`).catch((err: Error) => {
      if (request !== latest || !mounted) return null;
      clear(rows, h("tr", {}, h("td", { colspan: 11, class: "error-text" }, `Could not load captures: ${err.message} (trying again)`)));
      timer = window.setTimeout(() => void load(), 4000);
      return null;
    });
    if (!data || request !== latest || !mounted) return;
    clear(rows, ...data.results.map((c) => row(c, projectName.get(c.project) ?? String(c.project), projectRole.get(c.project), load, assignBar.checkbox(c))));
    if (!data.results.length) rows.append(h("tr", {}, h("td", { colspan: 11, class: "muted empty" }, "No captures match. Drop a file above to add one.")));
    clear(
      pager,
      h("span", { class: "muted" }, `${data.count} capture${data.count === 1 ? "" : "s"}`),
      data.previous ? h("button", { class: "btn", onclick: () => apply({ ...filters, page: filters.page - 1 }) }, "← Previous") : null,
      data.next ? h("button", { class: "btn", onclick: () => apply({ ...filters, page: filters.page + 1 }) }, "Next →") : null,
    );
    if (data.results.some((c) => busy(c.status) || busy(c.latest_run?.status))) timer = window.setTimeout(() => void load(), 2000);
  }

  function apply(next: Filters): void {
    if (!mounted) return;
    filters = next;
    selection.clear();
    drawNav();
    history.replaceState(null, "", `/${queryOf(filters)}`);
    void load();
  }

  await load();
  return () => {
    mounted = false;
    clearTimeout(timer);
    clearTimeout(searchDelay);
    document.removeEventListener("dragover", onDrag);
    document.removeEventListener("dragleave", onDrag);
    document.removeEventListener("drop", onDrop);
  };
}

/** What a failed capture offers: Retry when reading the original again may help, else what to do. */
function failedAction(c: CaptureSummary, reload: () => Promise<void>): HTMLElement {
  if (c.retryable) return retryButton(c, reload);
  return h("div", { class: "muted small", "data-testid": `fix-file-${c.id}` }, "The file itself cannot be read: fix or export it again, then upload it.");
}

/** Queue a failed capture's ingest again from its stored original, then refresh. */
function retryButton(c: CaptureSummary, reload: () => Promise<void>): HTMLElement {
  const retry = (e: Event) => {
    e.stopPropagation();
    post(`/api/captures/${c.id}/retry/`)
      .then(() => {
        toast(`${c.name}: queued again.`);
        return reload();
      })
      .catch((err: Error) => toast(`${c.name}: ${err.message}`, "error"));
  };
  return h("button", { class: "btn btn-small", "data-testid": `retry-${c.id}`, title: "Read the stored original again", onclick: retry }, "Retry");
}

const busy = (status: string | undefined) => status === "queued" || status === "processing";

/** Reviewers and admins may detect again, with the project's newest learnt model, until
 * someone opens the capture for review. */
export function canRedetect(c: CaptureSummary, role: Role | undefined): boolean {
  return (role === "reviewer" || role === "admin") && c.status === "ready" && !c.review_started && !busy(c.latest_run?.status);
}

function redetectButton(c: CaptureSummary, reload: () => Promise<void>): HTMLElement {
  const redetect = (e: Event) => {
    e.stopPropagation();
    (e.currentTarget as HTMLButtonElement).disabled = true;
    post(`/api/captures/${c.id}/redetect/`)
      .then(() => {
        toast(`${c.name}: detecting again with the project's model.`);
        return reload();
      })
      .catch((err: Error) => toast(`${c.name}: ${err.message}`, "error"));
  };
  return h("button", { class: "btn btn-small", "data-testid": `redetect-${c.id}`, title: "Nobody has opened it for review yet: propose its cuts again with the project's newest learnt model", onclick: redetect }, "Re-detect");
}

function cutsCell(c: CaptureSummary): HTMLElement {
  const run = c.latest_run;
  if (busy(run?.status)) return h("td", { class: "num muted" }, "detecting…");
  const adapted = run?.model_version ? h("span", { class: "muted small", title: `adapted from ${run.model_n_takes} reviewed take${run.model_n_takes === 1 ? "" : "s"}` }, ` v${run.model_version}`) : null;
  return h("td", { class: "num" }, String(run?.n_candidates ?? "—"), adapted);
}

function row(c: CaptureSummary, project: string, role: Role | undefined, reload: () => Promise<void>, check: HTMLElement): HTMLElement {
  const open = () => navigate(`/captures/${c.id}/`);
  const status = h("span", { class: `badge badge-${c.status}`, title: c.error ?? "" }, c.status);
  return h(
    "tr",
    { class: "capture-row", "data-testid": `capture-${c.id}`, tabindex: 0, onclick: open, onkeydown: (e: Event) => (e as KeyboardEvent).key === "Enter" && open() },
    h("td", { onclick: (e: Event) => e.stopPropagation() }, check),
    h("td", {}, clip(c.name, { href: `/captures/${c.id}/`, onclick: (e: Event) => e.preventDefault() }), c.status === "failed" && c.error ? h("div", { class: "error-text small" }, c.error) : null, c.status === "failed" ? failedAction(c, reload) : null),
    h("td", {}, project),
    h("td", {}, status),
    h("td", { class: "num" }, c.n_frames?.toLocaleString() ?? "—"),
    h("td", { class: "num" }, c.duration ? formatDuration(c.duration) : "—"),
    h("td", { class: "num" }, c.fps ?? "—"),
    h("td", { class: "num" }, c.n_joints ?? "—"),
    cutsCell(c),
    h("td", { class: "team-cell", "data-testid": `team-${c.id}` }, ...teamCell(c.team)),
    h("td", {}, c.created_at ? new Date(c.created_at).toLocaleString() : "", canRedetect(c, role) ? h("div", {}, redetectButton(c, reload)) : null),
  );
}
