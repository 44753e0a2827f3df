// Signing out is a POST carrying the CSRF token: the server refuses GET, so that a link or
// an image on another page cannot sign anyone out.

import { readCookie } from "../api/client";
import { h } from "./dom";

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
    h("button", { type: "submit", class: "btn btn-ghost", "data-testid": "logout" }, "Log out"),
  );
}
