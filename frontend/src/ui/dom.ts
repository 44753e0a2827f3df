// A tiny element builder: enough to keep page code declarative without a framework.

type Child = Node | string | number | null | undefined | false;
type Attrs = Record<string, string | number | boolean | EventListener | undefined | null>;

export function h<K extends keyof HTMLElementTagNameMap>(tag: K, attrs: Attrs = {}, ...children: Child[]): HTMLElementTagNameMap[K] {
  const el = document.createElement(tag);
  for (const [key, value] of Object.entries(attrs)) {
    if (value === undefined || value === null || value === false) continue;
    if (key.startsWith("on") && typeof value === "function") el.addEventListener(key.slice(2), value as EventListener);
    else if (key === "class") el.className = String(value);
    else if (value === true) el.setAttribute(key, "");
    else el.setAttribute(key, String(value));
  }
  append(el, children);
  return el;
}

/** Text that may be too long for its place: cut short with an ellipsis by CSS (``.clip``),
 * whole in its tooltip. An ``href`` makes it a link. */
export function clip(text: string, attrs: Attrs = {}): HTMLElement {
  const cls = ["clip", attrs.class].filter(Boolean).join(" ");
  return h(attrs.href ? "a" : "span", { ...attrs, class: cls, title: text }, text);
}

export function append(el: HTMLElement, children: Child[]): void {
  for (const child of children) {
    if (child === null || child === undefined || child === false) continue;
    el.append(child instanceof Node ? child : String(child));
  }
}

export function clear(el: HTMLElement, ...children: Child[]): HTMLElement {
  el.replaceChildren();
  append(el, children);
  return el;
}

let toastBox: HTMLElement | null = null;

/** A short notice in the corner; errors stay longer than confirmations. */
export function toast(message: string, kind: "info" | "error" = "info"): void {
  if (!toastBox || !toastBox.isConnected) {
    toastBox = h("div", { class: "toasts", role: "status", "aria-live": "polite" });
    document.body.append(toastBox);
  }
  const item = h("div", { class: `toast toast-${kind}` }, message);
  toastBox.append(item);
  setTimeout(() => item.remove(), kind === "error" ? 8000 : 3000);
}

/** A modal with a title, body and one close button; resolves when closed. */
export function dialog(title: string, body: Child[], button = "OK"): Promise<void> {
  return new Promise((resolve) => {
    const close = () => {
      backdrop.remove();
      resolve();
    };
    const ok = h("button", { class: "btn btn-primary", onclick: close, "data-testid": "dialog-ok" }, button);
    const backdrop = h(
      "div",
      { class: "modal-backdrop", role: "dialog", "aria-modal": "true", "aria-label": title },
      h("div", { class: "modal" }, h("h2", {}, title), h("div", { class: "modal-body" }, ...body), h("div", { class: "modal-actions" }, ok)),
    );
    document.body.append(backdrop);
    ok.focus();
  });
}

/** A modal asking to confirm an action that cannot be undone; resolves true on "ok". */
export function confirmDialog(title: string, body: Child[], ok: string, cancel = "Cancel"): Promise<boolean> {
  return new Promise((resolve) => {
    const close = (answer: boolean) => {
      backdrop.remove();
      document.removeEventListener("keydown", onKey, true);
      resolve(answer);
    };
    const onKey = (e: KeyboardEvent) => {
      if (e.key === "Escape") close(false);
    };
    const yes = h("button", { class: "btn btn-primary", onclick: () => close(true), "data-testid": "confirm-ok" }, ok);
    const no = h("button", { class: "btn", onclick: () => close(false), "data-testid": "confirm-cancel" }, cancel);
    const backdrop = h(
      "div",
      { class: "modal-backdrop", role: "dialog", "aria-modal": "true", "aria-label": title },
      h("div", { class: "modal" }, h("h2", {}, title), h("div", { class: "modal-body" }, ...body), h("div", { class: "modal-actions" }, no, yes)),
    );
    document.addEventListener("keydown", onKey, true);
    document.body.append(backdrop);
    yes.focus();
  });
}

export function formatDuration(seconds: number): string {
  if (!Number.isFinite(seconds)) return "—";
  const m = Math.floor(seconds / 60);
  const s = Math.round(seconds - m * 60);
  return m ? `${m} min ${String(s).padStart(2, "0")} s` : `${(Math.round(seconds * 10) / 10).toFixed(1)} s`;
}
