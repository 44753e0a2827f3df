// Sends edits to the server one at a time, each carrying the version of the review the
// server last returned. Edits are never merged or retried blindly: on a 409 the queue is
// dropped, the caller is told which edits were not saved, and the server's review wins.

import { api, ApiError } from "../api/client";
import type { Review } from "../api/types";
import { editRequest, findInsertedId, labelRequest, startedIds, type Edit } from "./state";

/** The review started differently from how this page showed it unstarted: another tab
 * started and edited it, or a newer detection run finished in between. */
class StartedElsewhere extends Error {
  constructor(readonly review: Review) {
    super("This review was started in another window, or new candidates arrived, since this page opened.");
  }
}

export interface SaverEvents {
  saved(review: Review, idle: boolean, renamed: Map<number, number>): void;
  conflict(current: Review, unsaved: string[], message: string): void;
  failed(current: Review | null, unsaved: string[], message: string): void;
  busy(pending: number): void;
}

/** How the saver reaches the server: the API client, or a stand-in server in unit tests. */
export type Send = <T>(method: string, url: string, body?: unknown) => Promise<T>;

export class Saver {
  private queue: { edit: Edit; title: string }[] = [];
  private running = false;
  private readonly ids = new Map<number, number>();

  constructor(
    private readonly captureId: number,
    public server: Review,
    private readonly events: SaverEvents,
    private readonly send: Send = api,
  ) {}

  get pending(): number {
    return this.queue.length;
  }

  /** Server id of a cut we inserted under a temporary negative id. */
  readonly resolve = (id: number): number => (id < 0 ? (this.ids.get(id) ?? id) : id);

  push(edits: Edit[], title: string): void {
    for (const edit of edits) this.queue.push({ edit, title });
    this.events.busy(this.queue.length);
    if (!this.running) void this.pump();
  }

  private async pump(): Promise<void> {
    this.running = true;
    while (this.queue.length) {
      const { edit } = this.queue[0];
      try {
        if (this.server.id === null) await this.start();
        const request =
          edit.kind === "label" || edit.kind === "attribute"
            ? labelRequest(this.captureId, this.server, edit, this.server.version)
            : editRequest(this.captureId, edit, this.server.version, this.resolve, this.server.id);
        const next = await this.send<Review>(request.method, request.url, request.body);
        const renamed = new Map<number, number>();
        if (edit.kind === "insert") {
          const id = findInsertedId(this.server, next, edit.frame);
          if (id !== undefined) {
            this.ids.set(edit.tempId, id);
            renamed.set(edit.tempId, id);
          }
        }
        this.server = next;
        this.queue.shift();
        this.events.saved(next, this.queue.length === 0, renamed);
      } catch (err) {
        await this.abandon(err);
      }
    }
    this.running = false;
    this.events.busy(0);
  }

  /** The first save starts the review (reading it did not); its candidates get real ids. */
  private async start(): Promise<void> {
    const started = await this.send<Review>("POST", `/api/captures/${this.captureId}/review/`);
    const renamed = startedIds(this.server, started);
    for (const [temp, id] of renamed) this.ids.set(temp, id);
    this.events.saved(started, false, renamed);
    // Not what the page showed: show what changed, send nothing.
    if (started.version !== this.server.version || started.run !== this.server.run) throw new StartedElsewhere(started);
    this.server = started;
  }

  private async abandon(err: unknown): Promise<void> {
    const unsaved = [...new Set(this.queue.map((q) => q.title))];
    this.queue = [];
    const message = err instanceof Error ? err.message : String(err);
    if (err instanceof StartedElsewhere) {
      this.server = err.review;
      this.events.conflict(err.review, unsaved, message);
      return;
    }
    const body = err instanceof ApiError ? (err.body as { review?: Review } | null) : null;
    if (err instanceof ApiError && err.status === 409 && body?.review) {
      this.server = body.review;
      this.events.conflict(body.review, unsaved, message);
      return;
    }
    try {
      this.server = await this.send<Review>("GET", `/api/captures/${this.captureId}/review/`);
      this.events.failed(this.server, unsaved, message);
    } catch {
      this.events.failed(null, unsaved, message);
    }
  }
}
