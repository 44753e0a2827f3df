// Signing out is a POST carrying the CSRF token: the server refuses GET, so that a link or
// an image on another page cannot sign anyone out. Beside it, the button that opens the
// change-password dialog (a plain button: it does not submit the form).

import { readCookie } from "../api/client";
import { h } from "./dom";
import { passwordButton } from "./password";

export function logoutButton(): HTMLFormElement {
  const token = h("input", { type: "hidden", name: "csrfmiddlewaretoken", value: "" });
  const fill = () => {
    token.value = readCookie(document.cookie, "csrftoken") ?? "";
  };
  fill();
  return h(
    "form",
    { class: "logout-form", method: "post", action: "/logout/", onsubmit: fill },
    token,
    passwordButton(),
    h("button", { type: "submit", class: "btn btn-ghost", "data-testid": "logout" }, "Log out"),
  );
}
