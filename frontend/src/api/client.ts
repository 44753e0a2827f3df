// A thin fetch wrapper: session cookie + CSRF header, JSON in and out, and one error
// type whose message is the server's own `detail` text.

export class ApiError extends Error {
  constructor(
    readonly status: number,
    message: string,
    readonly body: unknown,
  ) {
    super(message);
    this.name = "ApiError";
  }
}

export function readCookie(cookies: string, name: string): string | null {
  for (const part of cookies.split(";")) {
    const [key, ...rest] = part.trim().split("=");
    if (key === name) return decodeURIComponent(rest.join("="));
  }
  return null;
}

/** Turn a DRF error body into one readable line ("params.sigma: must be >= 0, got -1"). */
export function errorText(status: number, body: unknown): string {
  if (body && typeof body === "object") {
    const record = body as Record<string, unknown>;
    if (typeof record.detail === "string") return record.detail;
    const parts = flatten(record, "");
    if (parts.length) return parts.join("; ");
  }
  if (typeof body === "string" && body.trim() && !body.trimStart().startsWith("<")) {
    return body.trim().slice(0, 300);
  }
  return `The server answered ${status}.`;
}

function flatten(value: unknown, path: string): string[] {
  if (Array.isArray(value)) return [`${path}: ${value.join(" ")}`];
  if (value && typeof value === "object") {
    return Object.entries(value).flatMap(([k, v]) => flatten(v, path ? `${path}.${k}` : k));
  }
  return [`${path}: ${String(value)}`];
}

function csrfHeader(): Record<string, string> {
  const token = typeof document === "undefined" ? null : readCookie(document.cookie, "csrftoken");
  return token ? { "X-CSRFToken": token } : {};
}

export async function api<T>(method: string, url: string, body?: unknown): Promise<T> {
  const headers: Record<string, string> = { Accept: "application/json", ...csrfHeader() };
  const init: RequestInit = { method, headers, credentials: "same-origin" };
  if (body instanceof FormData) {
    init.body = body;
  } else if (body !== undefined) {
    headers["Content-Type"] = "application/json";
    init.body = JSON.stringify(body);
  }
  let response = await fetch(url, init);
  for (let attempt = 0; ; attempt++) {
    const wait = retryDelay(method, response.status, response.headers.get("Retry-After"), attempt);
    if (wait === null) break;
    await new Promise((resolve) => setTimeout(resolve, wait));
    response = await fetch(url, init);
  }
  const text = await response.text();
  let parsed: unknown = text;
  try {
    parsed = text ? JSON.parse(text) : null;
  } catch {
    // Not JSON (a proxy error page, say): keep the text for the message.
  }
  if (isLoggedOut(response.status, parsed) && typeof window !== "undefined") toLogin();
  if (!response.ok) throw new ApiError(response.status, errorText(response.status, parsed), parsed);
  return parsed as T;
}

/** Milliseconds to wait before asking again, or null to give the answer to the caller.

A server that is busy (429, e.g. many people opening one long take) did not run the
request: ask again after its Retry-After, a few times. A 502/503 may come after a write
ran, so only reads are asked again then. */
export function retryDelay(method: string, status: number, retryAfter: string | null, attempt: number): number | null {
  const busy = status === 429 || ((status === 502 || status === 503) && (method === "GET" || method === "HEAD"));
  if (!busy || retryAfter === null || attempt >= MAX_RETRIES) return null;
  const seconds = Number(retryAfter);
  if (!Number.isFinite(seconds) || seconds < 0) return null;
  return Math.min(seconds, MAX_RETRY_WAIT_S) * 1000;
}

const MAX_RETRIES = 3;
const MAX_RETRY_WAIT_S = 10;

/** DRF answers 403 (session auth) or 401 (token auth) when nobody is logged in. */
export function isLoggedOut(status: number, body: unknown): boolean {
  if (status === 401) return true;
  const detail = (body as { detail?: unknown } | null)?.detail;
  return status === 403 && typeof detail === "string" && /credentials were not provided/i.test(detail);
}

export function toLogin(): void {
  const next = encodeURIComponent(location.pathname + location.search);
  location.assign(`/login/?next=${next}`);
}

export const get = <T>(url: string) => api<T>("GET", url);
export const post = <T>(url: string, body?: unknown) => api<T>("POST", url, body ?? {});
export const patch = <T>(url: string, body: unknown) => api<T>("PATCH", url, body);

/** POST a multipart form with upload progress (0..1), which fetch cannot report; resolves
 * with the parsed answer, fails with the server's message, or with `interrupted` when the
 * connection breaks. */
export function postWithProgress<T>(url: string, form: FormData, onProgress: (share: number) => void, interrupted: string): Promise<T> {
  return new Promise((resolve, reject) => {
    const xhr = new XMLHttpRequest();
    xhr.open("POST", url);
    const token = readCookie(document.cookie, "csrftoken");
    if (token) xhr.setRequestHeader("X-CSRFToken", token);
    xhr.setRequestHeader("Accept", "application/json");
    xhr.upload.onprogress = (e) => e.lengthComputable && onProgress(e.loaded / e.total);
    xhr.onload = () => {
      let body: unknown = xhr.responseText;
      try {
        body = JSON.parse(xhr.responseText);
      } catch {
        // keep the text
      }
      if (xhr.status >= 200 && xhr.status < 300) resolve(body as T);
      else reject(new Error(errorText(xhr.status, body)));
    };
    xhr.onerror = () => reject(new Error(interrupted));
    xhr.send(form);
  });
}
