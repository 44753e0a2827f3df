// A small client-side router. Pages register a path pattern and a render function that
// returns its clean-up; links inside the app navigate without a full reload.

import { ApiError } from "./api/client";

export type Render = (root: HTMLElement, params: Record<string, string>) => Promise<() => void>;

const routes: { pattern: RegExp; keys: string[]; render: Render }[] = [];
let cleanup: (() => void) | null = null;
let root: HTMLElement | null = null;

/** `path` like "/captures/:id/"; a trailing slash is optional when matching. */
export function registerRoute(path: string, render: Render): void {
  const keys: string[] = [];
  const source = path.replace(/\/$/, "").replace(/:(\w+)/g, (_, key: string) => {
    keys.push(key);
    return "([^/]+)";
  });
  routes.push({ pattern: new RegExp(`^${source}/?$`), keys, render });
}

export function match(pathname: string): { render: Render; params: Record<string, string> } | null {
  for (const route of routes) {
    const m = route.pattern.exec(pathname);
    if (m) return { render: route.render, params: Object.fromEntries(route.keys.map((k, i) => [k, decodeURIComponent(m[i + 1])])) };
  }
  return null;
}

export function navigate(url: string): void {
  history.pushState(null, "", url);
  void show();
}

export async function show(): Promise<void> {
  if (!root) return;
  cleanup?.();
  cleanup = null;
  const found = match(location.pathname);
  if (!found) {
    root.replaceChildren(notFound(location.pathname));
    return;
  }
  try {
    cleanup = await found.render(root, found.params);
  } catch (err) {
    const { title, message, refusal } = failure(err);
    const box = document.createElement("div");
    box.className = "loading-page";
    box.dataset.testid = "page-failure";
    box.innerHTML = `<h1></h1><p></p><a href="/">← Captures</a>`;
    box.querySelector("h1")!.textContent = title;
    box.querySelector("p")!.textContent = message;
    if (!refusal) box.querySelector("p")!.className = "error-text";
    root.replaceChildren(box);
  }
}

/**
 * What a page that could not be shown says: a refusal (403: the caller's role, say) or a
 * missing thing (404) by its name, with the server's reason in plain text; anything else
 * is a failure, in red.
 */
export function failure(err: unknown): { title: string; message: string; refusal: boolean } {
  const message = err instanceof Error ? err.message : String(err);
  if (err instanceof ApiError && err.status === 403) return { title: "Not allowed", message, refusal: true };
  if (err instanceof ApiError && err.status === 404) return { title: "Not found", message, refusal: true };
  return { title: "Something went wrong", message, refusal: false };
}

function notFound(path: string): HTMLElement {
  const box = document.createElement("div");
  box.className = "loading-page";
  box.innerHTML = `<h1>Not found</h1><p></p><a href="/">← Captures</a>`;
  box.querySelector("p")!.textContent = `Nothing lives at ${path}.`;
  return box;
}

export function start(element: HTMLElement): void {
  root = element;
  window.addEventListener("popstate", () => void show());
  document.addEventListener("click", (e) => {
    const a = (e.target as HTMLElement).closest?.("a");
    if (!a || e.defaultPrevented || e.button !== 0 || e.metaKey || e.ctrlKey || a.target || !a.href) return;
    const url = new URL(a.href);
    if (url.origin !== location.origin || !match(url.pathname) || url.pathname.startsWith("/api/")) return;
    e.preventDefault();
    navigate(url.pathname + url.search);
  });
  void show();
}
