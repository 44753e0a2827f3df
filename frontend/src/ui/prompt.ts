// A modal asking for one line or paragraph of text; resolves with it, or null if cancelled.

import { h } from "./dom";

export function promptDialog(title: string, intro: string, ok: string, placeholder = ""): Promise<string | null> {
  return new Promise((resolve) => {
    const text = h("textarea", { class: "input prompt-text", rows: 4, placeholder, "data-testid": "prompt-text" });
    const close = (answer: string | null) => {
      backdrop.remove();
      document.removeEventListener("keydown", onKey, true);
      resolve(answer);
    };
    const onKey = (e: KeyboardEvent) => {
      if (e.key === "Escape") close(null);
    };
    const yes = h("button", { class: "btn btn-primary", "data-testid": "prompt-ok", onclick: () => text.value.trim() && close(text.value.trim()) }, ok);
    const no = h("button", { class: "btn", "data-testid": "prompt-cancel", onclick: () => close(null) }, "Cancel");
    const backdrop = h(
      "div",
      { class: "modal-backdrop", role: "dialog", "aria-modal": "true", "aria-label": title },
      h("div", { class: "modal" }, h("h2", {}, title), h("div", { class: "modal-body" }, h("p", {}, intro), text), h("div", { class: "modal-actions" }, no, yes)),
    );
    document.addEventListener("keydown", onKey, true);
    document.body.append(backdrop);
    text.focus();
  });
}

/** A modal asking for one short line (Enter answers, Escape cancels); resolves with it, or null. */
export function promptLine(title: string, intro: string, ok: string, placeholder = ""): Promise<string | null> {
  return new Promise((resolve) => {
    const input = h("input", { class: "input", type: "text", placeholder, autocomplete: "off", "data-testid": "prompt-line" }) as HTMLInputElement;
    const close = (answer: string | null) => {
      backdrop.remove();
      document.removeEventListener("keydown", onKey, true);
      resolve(answer);
    };
    const answer = () => input.value.trim() && close(input.value.trim());
    const onKey = (e: KeyboardEvent) => {
      if (e.key === "Escape") close(null);
      else if (e.key === "Enter") {
        e.preventDefault();
        answer();
      }
    };
    const yes = h("button", { class: "btn btn-primary", "data-testid": "prompt-ok", onclick: answer }, ok);
    const no = h("button", { class: "btn", "data-testid": "prompt-cancel", onclick: () => close(null) }, "Cancel");
    const backdrop = h(
      "div",
      { class: "modal-backdrop", role: "dialog", "aria-modal": "true", "aria-label": title },
      h("div", { class: "modal" }, h("h2", {}, title), h("div", { class: "modal-body" }, h("p", {}, intro), input), h("div", { class: "modal-actions" }, no, yes)),
    );
    document.addEventListener("keydown", onKey, true);
    document.body.append(backdrop);
    input.focus();
  });
}
