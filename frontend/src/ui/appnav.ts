// Links every page's top bar carries: the queue, the library and, for a project, its
// dashboard and team.

import { h } from "./dom";

export function appLinks(project?: number | null, role?: string | null): HTMLElement[] {
  const links = [
    h("a", { class: "btn btn-ghost", href: "/queue/", "data-testid": "nav-queue" }, "My queue"),
    h("a", { class: "btn btn-ghost", href: "/library/", "data-testid": "nav-library" }, "Library"),
  ];
  if (project) links.push(h("a", { class: "btn btn-ghost", href: `/projects/${project}/dashboard/`, "data-testid": "nav-dashboard" }, "Dashboard"));
  if (project && role && role !== "annotator") links.push(h("a", { class: "btn btn-ghost", href: `/projects/${project}/team/`, "data-testid": "nav-team" }, "Team"));
  return links;
}
