import "./library.css";
// The top bar of the library pages: breadcrumbs plus the links every page carries.

import { accountLinks, appLinks } from "../ui/appnav";
import { clip, h } from "../ui/dom";

// A crumb longer than this is a name (a capture's, a project's) that may be cut short.
const LONG_CRUMB = 16;

function crumb(text: string, href: string | null): HTMLElement {
  if (text.length > LONG_CRUMB) return href ? clip(text, { href }) : clip(text, { class: "current" });
  return href ? h("a", { href }, text) : h("strong", {}, text);
}

export function topbar(crumbs: [string, string | null][], project?: number, role?: string | null): HTMLElement {
  return h(
    "header",
    { class: "topbar" },
    h("a", { class: "brand", href: "/" }, "Cutroom"),
    h(
      "nav",
      { class: "crumbs" },
      ...crumbs.flatMap(([text, href], i) => [i ? h("span", {}, "/") : null, crumb(text, href)]),
    ),
    h("span", { class: "spacer" }),
    ...appLinks(project, role),
    ...accountLinks(),
  );
}
