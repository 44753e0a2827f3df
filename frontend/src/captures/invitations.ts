// Invitations to join projects: a person joins a project only by accepting one, so the
// capture list shows each pending invitation with who sent it, the role, and two buttons.

import { get, post } from "../api/client";
import type { MyInvitation } from "../api/types";
import { h, toast } from "../ui/dom";

export type Invitation = MyInvitation;

export function invitationsBox(onJoined: () => void): HTMLElement {
  const box = h("section", { class: "invitations", "data-testid": "invitations", hidden: true });

  const load = async () => {
    const invitations = await get<Invitation[]>("/api/invitations/");
    box.replaceChildren(...invitations.map(row));
    box.hidden = invitations.length === 0;
  };

  const answer = async (invitation: Invitation, verb: "accept" | "decline") => {
    try {
      await post(`/api/invitations/${invitation.id}/${verb}/`);
      toast(verb === "accept" ? `You joined ${invitation.project.name}.` : `Declined ${invitation.project.name}.`);
      if (verb === "accept") onJoined();
      else await load();
    } catch (error) {
      toast((error as Error).message, "error");
    }
  };

  const row = (invitation: Invitation) =>
    h(
      "div",
      { class: "invitation", "data-testid": "invitation" },
      h("span", {}, `${invitation.invited_by ?? "A project admin"} invites you to `, h("strong", {}, invitation.project.name), ` as ${invitation.role}.`),
      h("button", { class: "btn btn-primary", onclick: () => void answer(invitation, "accept") }, "Accept"),
      h("button", { class: "btn", onclick: () => void answer(invitation, "decline") }, "Decline"),
    );

  load().catch((error: Error) => toast(error.message, "error"));
  return box;
}
