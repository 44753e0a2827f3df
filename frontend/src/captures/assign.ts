// Assigning captures from the capture list (reviewers and admins): tick captures, pick
// annotators, optionally "each capture to N of them" (spread evenly by the server), assign.
// The Team column shows who is assigned and each review's state.

import { get } from "../api/client";
import type { CaptureSummary, Project } from "../api/types";
import { assign, STATE_TEXT, type Member } from "../queue/api";
import { clear, clip, h, toast } from "../ui/dom";

export function teamCell(team: CaptureSummary["team"]): (HTMLElement | string)[] {
  if (!team || (!team.assigned.length && !team.reviews.length)) return ["—"];
  const reviewed = new Map(team.reviews.map((r) => [r.annotator, r.status]));
  const names = [...new Set([...team.assigned, ...team.reviews.map((r) => r.annotator)])];
  return names.map((name) => {
    const status = reviewed.get(name);
    const state = status ?? "assigned";
    return h("span", { class: "who", title: team.assigned.includes(name) ? "assigned" : "picked it up" }, clip(name, { class: "who-name" }), " ", h("span", { class: `badge badge-q-${state}` }, STATE_TEXT[state]));
  });
}

export function assignmentBar(projects: Project[], project: () => number | null, selection: Set<number>, reload: () => void) {
  const el = h("div", { class: "assign-bar", "data-testid": "assign-bar", hidden: true });
  const manages = (id: number | null) => {
    const role = projects.find((p) => p.id === id)?.role;
    return role === "reviewer" || role === "admin";
  };

  // The annotators ticked and "each to N" survive redraws (ticking another capture redraws
  // the bar), and only the newest redraw may draw: members load asynchronously.
  const chosen = new Set<string>();
  let perCapture = "";
  let latest = 0;
  const members = new Map<number, Promise<Member[]>>();

  const draw = async () => {
    const id = project();
    const request = ++latest;
    if (!selection.size) {
      el.hidden = true;
      return;
    }
    el.hidden = false;
    if (!id || !manages(id)) {
      clear(el, h("span", { class: "muted" }, id ? "Only the project's reviewers and admins assign captures." : "Pick one project in the filter to assign its captures."));
      return;
    }
    if (!members.has(id)) members.set(id, get<Member[]>(`/api/projects/${id}/members/`));
    const people = await members.get(id)!;
    if (request !== latest) return;
    const boxes = people.map((m) => {
      const box = h("input", { type: "checkbox", value: m.username, checked: chosen.has(m.username), "data-testid": `assign-to-${m.username}` });
      box.addEventListener("change", () => (box.checked ? chosen.add(m.username) : chosen.delete(m.username)));
      return h("label", { class: "check" }, box, m.username);
    });
    const each = h("input", { class: "input input-small", type: "number", min: 1, placeholder: "all", value: perCapture, "data-testid": "assign-per-capture", "aria-label": "annotators per capture" });
    each.addEventListener("input", () => (perCapture = each.value));
    const go = async () => {
      const annotators = people.map((m) => m.username).filter((u) => chosen.has(u));
      if (!annotators.length) return toast("Tick at least one annotator.", "error");
      try {
        const made = await assign(id, [...selection], annotators, perCapture ? Number(perCapture) : null);
        toast(`${made.length} assignment${made.length === 1 ? "" : "s"} made.`);
        selection.clear();
        reload();
        el.hidden = true;
      } catch (err) {
        toast((err as Error).message, "error");
      }
    };
    clear(
      el,
      h("b", {}, `Assign ${selection.size} capture${selection.size === 1 ? "" : "s"} to`),
      ...boxes,
      h("span", { class: "muted" }, "each capture to"),
      each,
      h("span", { class: "muted" }, "of them"),
      h("button", { class: "btn btn-primary", "data-testid": "assign-go", onclick: () => void go() }, "Assign"),
    );
  };

  const checkbox = (c: CaptureSummary) => {
    const box = h("input", { type: "checkbox", "data-testid": `select-${c.id}`, "aria-label": `select ${c.name}`, checked: selection.has(c.id) });
    box.addEventListener("change", () => {
      if (box.checked) selection.add(c.id);
      else selection.delete(c.id);
      void draw();
    });
    return box;
  };
  return { el, checkbox };
}
