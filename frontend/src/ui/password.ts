// Changing one's own password: a dialog opened from the top bar. The server checks the
// current password and the strength of the new one and says what is wrong; this page only
// catches a mistyped confirmation before asking it.

import { ApiError, post } from "../api/client";
import { h, toast } from "./dom";

/** What stops these fields from being sent, or null when they can be. */
export function passwordProblem(current: string, next: string, confirm: string): string | null {
  if (!current) return "Type your current password.";
  if (!next) return "Type a new password.";
  if (next !== confirm) return "The new password and its confirmation differ.";
  if (next === current) return "The new password is the same as the current one.";
  return null;
}

export function passwordButton(): HTMLButtonElement {
  return h("button", { type: "button", class: "btn btn-ghost", "data-testid": "change-password", onclick: () => passwordDialog() }, "Password");
}

export function passwordDialog(): void {
  const field = (testid: string, autocomplete: string) => h("input", { type: "password", class: "input", autocomplete, "data-testid": testid });
  const current = field("password-current", "current-password");
  const next = field("password-new", "new-password");
  const confirm = field("password-confirm", "new-password");
  const problem = h("p", { class: "error-text password-error", role: "alert", "data-testid": "password-error" });
  const close = () => {
    backdrop.remove();
    document.removeEventListener("keydown", onKey, true);
  };
  const onKey = (e: KeyboardEvent) => {
    if (e.key === "Escape") close();
  };
  const save = h("button", { type: "submit", class: "btn btn-primary", "data-testid": "password-save" }, "Change password");
  const submit = async (e: Event) => {
    e.preventDefault();
    const local = passwordProblem(current.value, next.value, confirm.value);
    problem.textContent = local ?? "";
    if (local) return;
    save.disabled = true;
    try {
      const answer = await post<{ detail: string }>("/api/auth/password/", { current_password: current.value, new_password: next.value });
      close();
      toast(answer.detail);
    } catch (err) {
      problem.textContent = err instanceof ApiError ? err.message : String(err);
    } finally {
      save.disabled = false;
    }
  };
  const label = (text: string, input: HTMLInputElement) => h("label", { class: "field" }, h("span", {}, text), input);
  const form = h(
    "form",
    { class: "modal", onsubmit: submit },
    h("h2", {}, "Change your password"),
    h("div", { class: "modal-body" }, h("p", {}, "Your other sessions and your API tokens will be signed out."), label("Current password", current), label("New password", next), label("New password again", confirm), problem),
    h("div", { class: "modal-actions" }, h("button", { type: "button", class: "btn", "data-testid": "password-cancel", onclick: close }, "Cancel"), save),
  );
  const backdrop = h("div", { class: "modal-backdrop", role: "dialog", "aria-modal": "true", "aria-label": "Change your password" }, form);
  document.addEventListener("keydown", onKey, true);
  document.body.append(backdrop);
  current.focus();
}
