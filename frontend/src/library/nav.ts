import "./library.css";
// The top bar of the library pages: breadcrumbs plus the links every page carries.

import { accountLinks, appLinks } from "../ui/appnav";
import { h } from "../ui/dom";

export function topbar(crumbs: [string, string | null][], project?: number, role?: string | null): HTMLElement {
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
    ...appLinks(project, role),
    ...accountLinks(),
  );
}
