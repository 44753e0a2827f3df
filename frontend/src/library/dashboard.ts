// The project dashboard (reviewers, admins): captures by review state, each annotator's
// throughput and edits from the audit log, and agreement per label.

import { get } from "../api/client";
import { clear, clip, h } from "../ui/dom";
import { teamCell } from "../captures/assign";
import { topbar } from "./nav";
import type { CaptureState, Dashboard } from "./types";

const STATE_NAMES: Record<CaptureState, string> = { unreviewed: "Unreviewed", in_review: "In review", agreed: "Agreed", adjudicated: "Adjudicated" };
const num = (v: number | null, digits = 2) => (v === null ? "—" : v.toFixed(digits));

const table = (head: string[], rows: HTMLElement[], testid: string) =>
  h("table", { class: "captures", "data-testid": testid }, h("thead", {}, h("tr", {}, ...head.map((t) => h("th", {}, t)))), h("tbody", {}, ...rows));

export async function renderDashboard(root: HTMLElement, projectId: number): Promise<() => void> {
  const d = await get<Dashboard>(`/api/projects/${projectId}/dashboard/`);
  const states = (Object.keys(STATE_NAMES) as CaptureState[]).map((s) =>
    h("div", { class: `stat state-${s}` }, h("b", { "data-testid": `state-${s}` }, String(d.states[s])), h("span", {}, STATE_NAMES[s])),
  );
  const captures = d.captures.map((c) =>
    h(
      "tr",
      { "data-testid": `dash-capture-${c.id}` },
      h("td", {}, clip(c.name, { href: `/captures/${c.id}/` })),
      h("td", {}, h("span", { class: `badge state-badge state-${c.state}` }, STATE_NAMES[c.state])),
      h("td", { class: "num" }, `${c.submitted} / ${c.reviews}`),
      h("td", { class: "team-cell" }, ...teamCell({ assigned: c.assigned ?? [], reviews: c.review_states ?? [] })),
      h("td", { class: "num" }, num(c.boundary_f1)),
      h("td", { class: "num" }, num(c.label_agreement)),
      h("td", {}, c.submitted > 0 ? h("a", { class: "btn", href: `/captures/${c.id}/adjudicate/`, "data-testid": `adjudicate-${c.id}` }, "Adjudicate") : null),
    ),
  );
  const people = d.annotators.map((a) =>
    h(
      "tr",
      {},
      h("td", {}, clip(a.username)),
      h("td", { class: "num" }, String(a.submitted)),
      h("td", { class: "num" }, String(a.in_progress)),
      h("td", { class: "num" }, String(a.edits_total)),
      h("td", {}, Object.entries(a.edits).filter(([, n]) => n).map(([k, n]) => `${k} ${n}`).join(" · ") || "—"),
      h("td", { class: "num" }, num(a.edits_per_review, 1)),
      h("td", { class: "num" }, a.median_minutes_per_review === null ? "—" : `${num(a.median_minutes_per_review, 1)} min`),
    ),
  );
  const labels = d.labels.map((l) => h("tr", {}, h("td", {}, clip(l.label)), h("td", { class: "num" }, num(l.overlap)), h("td", { class: "num" }, l.frames.toLocaleString()), h("td", { class: "num" }, String(l.captures))));
  clear(
    root,
    h(
      "div",
      { class: "list-page" },
      // Only reviewers and admins reach a dashboard: their links include the team.
      topbar([["Captures", "/"], ["Dashboard", null]], projectId, "reviewer"),
      h(
        "main",
        { class: "list-main" },
        h("div", { class: "stat-grid dash-states" }, ...states, h("div", { class: "stat" }, h("b", {}, `${d.library.total}`), h("span", {}, `library segments (${d.library.gold} gold)`))),
        h("h2", {}, "Captures"),
        table(["Capture", "State", "Submitted / reviews", "Team", "Boundary F1", "Label agreement", ""], captures, "dash-captures"),
        h("h2", {}, "Annotators"),
        table(["Annotator", "Submitted", "In progress", "Edits", "By kind", "Edits per review", "Median time per review"], people, "dash-annotators"),
        h("h2", {}, "Agreement per label"),
        labels.length ? table(["Label", "Overlap (IoU)", "Frames", "Captures"], labels, "dash-labels") : h("p", { class: "muted" }, "No capture has two submitted reviews yet."),
      ),
    ),
  );
  return () => undefined;
}
