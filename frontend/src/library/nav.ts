import "./library.css";
// The top bar of the library pages: breadcrumbs plus links to the library and, for a
// project, its dashboard.

import { h } from "../ui/dom";
import { logoutButton } from "../ui/logout";

export function topbar(crumbs: [string, string | null][], project?: number): HTMLElement {
  return h(
    "header",
    { class: "topbar" },
    h("a", { class: "brand", href: "/" }, "Cutroom"),
    h(
      "nav",
      { class: "crumbs" },
      ...crumbs.flatMap(([text, href], i) => [i ? h("span", {}, "/") : null, href ? h("a", { href }, text) : h("strong", {}, text)]),
    ),
    h("span", { class: "spacer" }),
    h("a", { class: "btn btn-ghost", href: "/library/", "data-testid": "nav-library" }, "Library"),
    project ? h("a", { class: "btn btn-ghost", href: `/projects/${project}/dashboard/`, "data-testid": "nav-dashboard" }, "Dashboard") : null,
    logoutButton(),
  );
}
