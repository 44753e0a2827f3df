// Links every page's top bar carries, in the same order on every page: the queue, the
// library and, for a project its reviewers and admins run, its dashboard and team; then who
// is signed in and "Log out". An annotator is not offered pages that would refuse them.

import { get } from "../api/client";
import type { Me } from "../api/types";
import { h } from "./dom";
import { logoutButton } from "./logout";

let me: Promise<Me> | null = null;

/** The signed-in user's name (filled in once /api/me/ answers, asked once per page load) and
 * the sign-out button. */
export function accountLinks(username?: string): HTMLElement[] {
  const user = h("span", { class: "user", "data-testid": "nav-user", title: username ?? "" }, username ?? "");
  if (username === undefined) {
    me ??= get<Me>("/api/me/");
    me.then((m) => {
      user.textContent = m.username;
      user.title = m.username;
    }).catch(() => undefined);
  }
  return [user, logoutButton()];
}

export function appLinks(project?: number | null, role?: string | null): HTMLElement[] {
  const links = [
    h("a", { class: "btn btn-ghost", href: "/queue/", "data-testid": "nav-queue" }, "My queue"),
    h("a", { class: "btn btn-ghost", href: "/library/", "data-testid": "nav-library" }, "Library"),
  ];
  if (project && role && role !== "annotator") {
    links.push(h("a", { class: "btn btn-ghost", href: `/projects/${project}/dashboard/`, "data-testid": "nav-dashboard" }, "Dashboard"));
    links.push(h("a", { class: "btn btn-ghost", href: `/projects/${project}/team/`, "data-testid": "nav-team" }, "Team"));
  }
  return links;
}
