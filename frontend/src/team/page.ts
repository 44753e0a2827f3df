// The Team page of a project: members and their roles, invitations, accounts (site admins),
// the project's assignment rule, and its label taxonomy. Admins change things; reviewers
// see the members; annotators are told the page is not theirs (the API refuses them too).

import { api, ApiError, get, patch, post } from "../api/client";
import type { Invitation, Label, Me, Project, Role } from "../api/types";
import type { Member } from "../queue/api";
import { accountLinks, appLinks } from "../ui/appnav";
import { clear, clip, confirmDialog, dialog, h, toast } from "../ui/dom";
import { attributeEditor } from "./attributes";
import { taxonomyEditor } from "./taxonomy";
import "./team.css";

const ROLES: Role[] = ["annotator", "reviewer", "admin"];

export async function renderTeam(root: HTMLElement, projectId: number): Promise<() => void> {
  const [me, project] = await Promise.all([get<Me>("/api/me/"), get<Project>(`/api/projects/${projectId}/`)]);
  const isAdmin = project.role === "admin";
  const main = h("main", { class: "list-main team-main" });
  clear(
    root,
    h(
      "div",
      { class: "list-page team-page" },
      h("header", { class: "topbar" }, h("a", { class: "brand", href: "/" }, "Cutroom"), h("nav", { class: "crumbs" }, h("a", { href: "/" }, "Captures"), h("span", {}, "/"), clip(project.name), h("span", {}, "/"), h("strong", {}, "Team")), h("span", { class: "spacer" }), ...appLinks(project.id, project.role), ...accountLinks(me.username)),
      main,
    ),
  );
  if (project.role === "annotator") {
    clear(main, h("div", { class: "refusal", "data-testid": "team-refused" }, h("h1", {}, "Team"), h("p", {}, "Only the project's reviewers and admins see its team. Ask an admin of this project if you need a different role.")));
    return () => {};
  }

  const members = h("tbody", { "data-testid": "members" });
  const invitations = h("ul", { class: "invites", "data-testid": "pending-invitations" });

  async function loadMembers(): Promise<void> {
    const rows = await get<Member[]>(`/api/projects/${projectId}/members/`);
    clear(members, ...rows.map(memberRow));
  }

  function memberRow(m: Member): HTMLElement {
    const role = isAdmin
      ? h("select", { class: "select", "data-testid": `role-${m.username}`, "aria-label": `role of ${m.username}` }, ...ROLES.map((r) => h("option", { value: r, selected: r === m.role }, r)))
      : h("span", { "data-testid": `role-${m.username}` }, m.role);
    if (role instanceof HTMLSelectElement) role.addEventListener("change", () => void changeRole(m, role));
    return h(
      "tr",
      { "data-testid": `member-${m.username}` },
      h("td", {}, clip(m.username), m.id === me.id ? h("span", { class: "muted" }, " (you)") : null),
      h("td", {}, role),
      h("td", {}, h("a", { class: "btn btn-small", href: `/queue/?project=${projectId}&user=${encodeURIComponent(m.username)}` }, "Queue")),
      h(
        "td",
        {},
        isAdmin ? h("button", { class: "btn btn-small", "data-testid": `remove-${m.username}`, onclick: () => void remove(m) }, "Remove") : null,
        me.can_create_accounts && m.id !== me.id ? h("button", { class: "btn btn-small", "data-testid": `reset-password-${m.username}`, onclick: () => void resetPassword(m) }, "Reset password") : null,
      ),
    );
  }

  async function resetPassword(m: Member): Promise<void> {
    const ok = await confirmDialog(`Reset the password of ${m.username}?`, [h("p", {}, "They are signed out everywhere and their API tokens stop working; you get a one-time password to give them.")], "Reset");
    if (!ok) return;
    try {
      const made = await post<{ username: string; password: string }>(`/api/auth/users/${m.id}/password-reset/`);
      await oneTimePassword(`New password for ${made.username}`, made.password);
    } catch (err) {
      toast(err instanceof ApiError ? err.message : String(err), "error");
    }
  }

  async function changeRole(m: Member, select: HTMLSelectElement): Promise<void> {
    try {
      await patch(`/api/projects/${projectId}/members/${m.id}/`, { role: select.value });
      toast(`${m.username} is now ${select.value}.`);
    } catch (err) {
      toast((err as Error).message, "error");
    }
    await loadMembers();
  }

  async function remove(m: Member): Promise<void> {
    const ok = await confirmDialog(`Remove ${m.username}?`, [h("p", {}, "They lose access to the project. Their reviews stay.")], "Remove");
    if (!ok) return;
    try {
      await api("DELETE", `/api/projects/${projectId}/members/${m.id}/`);
      toast(`${m.username} was removed.`);
    } catch (err) {
      toast((err as Error).message, "error");
    }
    await loadMembers();
  }

  async function loadInvitations(): Promise<void> {
    const rows = await get<Invitation[]>(`/api/projects/${projectId}/invitations/`);
    clear(invitations, ...rows.map((i) => h("li", { "data-testid": `invitation-${i.username}` }, h("b", {}, i.username), ` as ${i.role}, until ${new Date(i.expires_at).toLocaleDateString()} `, h("button", { class: "btn btn-small", "data-testid": `cancel-invitation-${i.username}`, onclick: () => void cancel(i) }, "Cancel"))));
    if (!rows.length) invitations.append(h("li", { class: "muted" }, "No pending invitations."));
  }

  async function cancel(i: Invitation): Promise<void> {
    try {
      await api("DELETE", `/api/projects/${projectId}/invitations/${i.id}/`);
      toast(`Invitation of ${i.username} cancelled.`);
    } catch (err) {
      toast((err as Error).message, "error");
    }
    await loadInvitations();
  }

  const userForm = (testid: string, submitText: string, send: (username: string, role: Role) => Promise<void>) => {
    const name = h("input", { class: "input", placeholder: "username", "data-testid": `${testid}-username`, required: true });
    const role = h("select", { class: "select", "data-testid": `${testid}-role` }, ...ROLES.map((r) => h("option", { value: r }, r)));
    const form = h("form", { class: "inline-form", "data-testid": testid }, name, role, h("button", { class: "btn btn-primary", type: "submit" }, submitText));
    form.addEventListener("submit", (e) => {
      e.preventDefault();
      if (!name.value.trim()) return;
      void send(name.value.trim(), role.value as Role).then(() => {
        name.value = "";
      });
    });
    return form;
  };

  const invite = async (username: string, role: Role) => {
    try {
      const answer = await post<{ detail?: string; username?: string; role?: string }>(`/api/projects/${projectId}/members/`, { username, role });
      toast(answer.detail ?? `${username} is now ${role}.`);
    } catch (err) {
      toast((err as Error).message, "error");
    }
    await Promise.all([loadMembers(), loadInvitations()]);
  };

  const createAccount = async (username: string, role: Role) => {
    try {
      const made = await post<{ username: string; password: string }>(`/api/projects/${projectId}/members/new-account/`, { username, role });
      await oneTimePassword(`Account ${made.username} created`, made.password);
    } catch (err) {
      toast(err instanceof ApiError ? err.message : String(err), "error");
    }
    await loadMembers();
  };

  const pick = h("input", { type: "checkbox", "data-testid": "pick-unassigned", checked: project.annotators_pick_unassigned !== false, disabled: !isAdmin });
  pick.addEventListener("change", () => {
    patch(`/api/projects/${projectId}/`, { annotators_pick_unassigned: pick.checked })
      .then(() => toast(pick.checked ? "Annotators may pick unassigned captures." : "Annotators review only what is assigned to them."))
      .catch((err: Error) => toast(err.message, "error"));
  });

  append(main, [
    h("section", { class: "team-section" }, h("h2", {}, "Members"), h("table", { class: "captures members" }, h("thead", {}, h("tr", {}, ...["User", "Role", "Queue", ""].map((t) => h("th", {}, t)))), members)),
    isAdmin
      ? h(
          "section",
          { class: "team-section" },
          h("h2", {}, "Add people"),
          h("p", { class: "muted", "data-testid": "invite-note" }, inviteNote(me.can_see_accounts)),
          userForm("invite-form", "Invite", invite),
          h("h3", {}, "Pending invitations"),
          invitations,
          me.can_create_accounts ? h("h3", {}, "Create an account (site admins)") : null,
          me.can_create_accounts ? userForm("create-form", "Create with one-time password", createAccount) : null,
        )
      : null,
    h("section", { class: "team-section" }, h("h2", {}, "Assignments"), h("label", { class: "check" }, pick, " Annotators may also pick captures nobody assigned to them")),
    isAdmin ? taxonomyEditor(project) : null,
    isAdmin ? attributeEditor(project) : null,
  ]);
  await loadMembers();
  if (isAdmin) await loadInvitations();
  return () => {};
}

/** What the invite form promises: to a site admin (who may see accounts) that a name no
 * account has is refused; to anyone else, the same answer whether or not it exists. */
export function inviteNote(canSeeAccounts: boolean): string {
  return canSeeAccounts
    ? "An existing user is invited and joins once they accept. As a site admin you are told when no account has the name."
    : "An existing user is invited and joins once they accept; the answer is the same whether or not the name exists.";
}

function oneTimePassword(title: string, password: string): Promise<void> {
  return dialog(title, [
    h("p", {}, "Give this one-time password to the person; it is shown only now. At their first sign-in with it they choose their own password."),
    h("pre", { class: "one-time-password", "data-testid": "one-time-password" }, password),
  ], "I have noted it");
}

function append(el: HTMLElement, children: (HTMLElement | null)[]): void {
  for (const child of children) if (child) el.append(child);
}

export type { Label };
