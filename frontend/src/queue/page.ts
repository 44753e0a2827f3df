// My queue: the captures assigned to me and the reviews I started, oldest first, by state
// (assigned, in progress, returned, submitted), with duration, candidates and the
// reviewer's comment on a returned review. Reviewers and admins pick a project and a
// member to see that member's queue, and unassign or reassign from it.

import { api, get, patch } from "../api/client";
import type { Me } from "../api/types";
import { accountLinks, appLinks } from "../ui/appnav";
import { clear, clip, formatDuration, h, toast } from "../ui/dom";
import { loadQueue, STATE_TEXT, type Assignment, type Member, type QueueItem, type QueueState } from "./api";
import "./queue.css";

const FILTERS: ("" | QueueState)[] = ["", "assigned", "in_progress", "returned", "submitted"];

export async function renderQueue(root: HTMLElement): Promise<() => void> {
  const me = await get<Me>("/api/me/");
  const q = new URLSearchParams(location.search);
  let project = Number(q.get("project")) || null;
  let user = q.get("user") || null;
  let state: "" | QueueState = (q.get("state") as QueueState) || "";
  const role = () => me.projects.find((p) => p.id === project)?.role ?? null;
  const manages = () => role() === "reviewer" || role() === "admin";

  const tabs = h("div", { class: "queue-tabs", role: "tablist" });
  const body = h("tbody", { "data-testid": "queue-rows" });
  const who = h("span", {});
  const projectSelect = h(
    "select",
    { class: "select", "data-testid": "queue-project", "aria-label": "project" },
    h("option", { value: "" }, "All projects"),
    ...me.projects.map((p) => h("option", { value: String(p.id), selected: p.id === project }, p.name)),
  );
  projectSelect.addEventListener("change", () => {
    project = Number(projectSelect.value) || null;
    user = null;
    void load();
  });
  const nav = h("span", { class: "nav-links" });
  clear(
    root,
    h(
      "div",
      { class: "list-page queue-page" },
      h("header", { class: "topbar" }, h("a", { class: "brand", href: "/" }, "Cutroom"), h("nav", { class: "crumbs" }, h("a", { href: "/" }, "Captures"), h("span", {}, "/"), h("strong", {}, "My queue")), h("span", { class: "spacer" }), nav, ...accountLinks(me.username)),
      h(
        "main",
        { class: "list-main" },
        h("div", { class: "filters" }, projectSelect, who, tabs),
        h("table", { class: "captures queue" }, h("thead", {}, h("tr", {}, ...["Capture", "State", "Since", "Duration", "Candidates", "Reviewer's comment", ""].map((t) => h("th", {}, t)))), body),
      ),
    ),
  );

  async function whoSelect(): Promise<void> {
    clear(who);
    if (!project || !manages()) return;
    const members = await get<Member[]>(`/api/projects/${project}/members/`);
    const select = h(
      "select",
      { class: "select", "data-testid": "queue-user", "aria-label": "whose queue" },
      ...members.map((m) => h("option", { value: m.username, selected: m.username === (user ?? me.username) }, m.username === me.username ? `${m.username} (me)` : m.username)),
    );
    select.addEventListener("change", () => {
      user = select.value === me.username ? null : select.value;
      void load();
    });
    clear(who, h("label", { class: "muted" }, "Queue of "), select);
  }

  async function load(): Promise<void> {
    const query = new URLSearchParams();
    if (project) query.set("project", String(project));
    if (user) query.set("user", user);
    if (state) query.set("state", state);
    history.replaceState(null, "", `/queue/${query.toString() ? `?${query}` : ""}`);
    // As on the capture list: the project filtered on, else the only one there is.
    const navProject = project ?? (me.projects.length === 1 ? me.projects[0] : null)?.id ?? null;
    clear(nav, ...appLinks(navProject, me.projects.find((p) => p.id === navProject)?.role ?? null));
    await whoSelect();
    const [items, assignments] = await Promise.all([
      loadQueue(project, user),
      user && project ? get<Assignment[]>(`/api/projects/${project}/assignments/`) : Promise.resolve([] as Assignment[]),
    ]);
    const members = user && project ? await get<Member[]>(`/api/projects/${project}/members/`) : [];
    drawTabs(items);
    const shown = items.filter((i) => !state || i.state === state);
    clear(body, ...shown.map((i) => row(i, assignments.find((a) => a.capture.id === i.capture.id && a.annotator === user), members)));
    if (!shown.length) body.append(h("tr", {}, h("td", { colspan: 7, class: "muted empty" }, items.length ? "Nothing in this state." : "Nothing is assigned yet.")));
  }

  function drawTabs(items: QueueItem[]): void {
    clear(
      tabs,
      ...FILTERS.map((f) => {
        const n = items.filter((i) => !f || i.state === f).length;
        return h("button", { class: `btn btn-ghost${f === state ? " active" : ""}`, role: "tab", "data-testid": `queue-tab-${f || "all"}`, onclick: () => { state = f; void load(); } }, `${f ? STATE_TEXT[f] : "all"} (${n})`);
      }),
    );
  }

  function row(i: QueueItem, assignment: Assignment | undefined, members: Member[]): HTMLElement {
    const open = h("a", { class: "btn btn-small", href: `/captures/${i.capture.id}/`, "data-testid": `queue-open-${i.capture.id}` }, i.state === "assigned" ? "Start" : i.state === "submitted" ? "View" : "Continue");
    const actions: HTMLElement[] = [open];
    if (assignment) {
      actions.push(h("button", { class: "btn btn-small", "data-testid": `unassign-${i.capture.id}`, onclick: () => void unassign(assignment) }, "Unassign"));
      const others = members.filter((m) => m.username !== assignment.annotator);
      const to = h("select", { class: "select select-small", "data-testid": `reassign-${i.capture.id}`, "aria-label": "reassign to" }, h("option", { value: "" }, "Reassign to…"), ...others.map((m) => h("option", { value: m.username }, m.username)));
      to.addEventListener("change", () => to.value && void reassign(assignment, to.value));
      actions.push(to);
    }
    return h(
      "tr",
      { class: `queue-row state-${i.state}`, "data-testid": `queue-item-${i.capture.id}`, "data-state": i.state },
      h("td", {}, clip(i.capture.name, { href: `/captures/${i.capture.id}/` }), i.assigned ? null : h("span", { class: "muted small" }, " (picked)")),
      h("td", {}, h("span", { class: `badge badge-q-${i.state}` }, STATE_TEXT[i.state])),
      h("td", { title: i.since }, new Date(i.since).toLocaleString()),
      h("td", { class: "num" }, i.capture.duration ? formatDuration(i.capture.duration) : "—"),
      h("td", { class: "num" }, i.capture.n_candidates ?? "—"),
      h("td", { class: "comment", "data-testid": `queue-comment-${i.capture.id}` }, i.state === "returned" ? i.review?.return_comment ?? "" : ""),
      h("td", { class: "actions" }, ...actions),
    );
  }

  async function unassign(a: Assignment): Promise<void> {
    try {
      await api("DELETE", `/api/projects/${project}/assignments/${a.id}/`);
      toast(`${a.capture.name} is no longer assigned to ${a.annotator}.`);
    } catch (err) {
      toast((err as Error).message, "error");
    }
    await load();
  }

  async function reassign(a: Assignment, to: string): Promise<void> {
    try {
      await patch(`/api/projects/${project}/assignments/${a.id}/`, { annotator: to });
      toast(`${a.capture.name} now goes to ${to}.`);
    } catch (err) {
      toast((err as Error).message, "error");
    }
    await load();
  }

  await load();
  return () => {};
}
