// Assigning captures from the capture list (reviewers and admins): tick captures, pick
// annotators, optionally "each capture to N of them" (spread evenly by the server), assign.
// The Team column shows who is assigned and each review's state.

import { get } from "../api/client";
import type { CaptureSummary, Project } from "../api/types";
import { assign, STATE_TEXT, type Member } from "../queue/api";
import { clear, h, toast } from "../ui/dom";

export function teamCell(team: CaptureSummary["team"]): (HTMLElement | string)[] {
  if (!team || (!team.assigned.length && !team.reviews.length)) return ["—"];
  const reviewed = new Map(team.reviews.map((r) => [r.annotator, r.status]));
  const names = [...new Set([...team.assigned, ...team.reviews.map((r) => r.annotator)])];
  return names.map((name) => {
    const status = reviewed.get(name);
    const state = status ?? "assigned";
    return h("span", { class: "who", title: team.assigned.includes(name) ? "assigned" : "picked it up" }, `${name} `, h("span", { class: `badge badge-q-${state}` }, STATE_TEXT[state]));
  });
}

export function assignmentBar(projects: Project[], project: () => number | null, selection: Set<number>, reload: () => void) {
  const el = h("div", { class: "assign-bar", "data-testid": "assign-bar", hidden: true });
  const manages = (id: number | null) => {
    const role = projects.find((p) => p.id === id)?.role;
    return role === "reviewer" || role === "admin";
  };

  const draw = async () => {
    const id = project();
    if (!selection.size) {
      el.hidden = true;
      return;
    }
    el.hidden = false;
    if (!id || !manages(id)) {
      clear(el, h("span", { class: "muted" }, id ? "Only the project's reviewers and admins assign captures." : "Pick one project in the filter to assign its captures."));
      return;
    }
    const members = await get<Member[]>(`/api/projects/${id}/members/`);
    const boxes = members.map((m) => {
      const box = h("input", { type: "checkbox", value: m.username, "data-testid": `assign-to-${m.username}` });
      return { box, label: h("label", { class: "check" }, box, m.username) };
    });
    const each = h("input", { class: "input input-small", type: "number", min: 1, placeholder: "all", "data-testid": "assign-per-capture", "aria-label": "annotators per capture" });
    const go = async () => {
      const annotators = boxes.filter((b) => b.box.checked).map((b) => b.box.value);
      if (!annotators.length) return toast("Tick at least one annotator.", "error");
      try {
        const made = await assign(id, [...selection], annotators, each.value ? Number(each.value) : null);
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
      ...boxes.map((b) => b.label),
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
