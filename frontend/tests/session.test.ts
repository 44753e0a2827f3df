import { describe, expect, it } from "vitest";
import { ApiError } from "../src/api/client";
import type { Review } from "../src/api/types";
import { ReviewSession, type SessionView } from "../src/review/session";
import { applyEdit, type Edit } from "../src/review/state";
import { cut, review } from "./fixtures";

const N = 1000;

/**
 * A stand-in for the review API over one review: it applies each request with the same
 * rules as the page's prediction, bumps the version, and refuses a stale version with the
 * server's 409 body. `requests` records what the session sent.
 */
class StandInServer {
  requests: { method: string; url: string; body: Record<string, unknown> }[] = [];
  nextId = 100;
  /** The states before each edit, and the undone ones: undo/redo step through them. */
  past: Review[] = [];
  future: Review[] = [];

  constructor(public current: Review) {}

  send = async <T>(method: string, url: string, body?: unknown): Promise<T> => {
    const b = (body ?? {}) as Record<string, unknown>;
    this.requests.push({ method, url, body: b });
    if (method === "GET") return this.current as T;
    if (b.version !== undefined && b.version !== this.current.version) {
      throw new ApiError(409, "stale version", { review: this.current });
    }
    this.current = { ...this.answer(url, b), version: this.current.version + 1 };
    return this.current as T;
  };

  private answer(url: string, b: Record<string, unknown>): Review {
    if (url.endsWith("/submit/")) return { ...this.current, status: "submitted" };
    const [from, to] = url.endsWith("/undo/") ? [this.past, this.future] : [this.future, this.past];
    if (url.endsWith("/undo/") || url.endsWith("/redo/")) {
      to.push(this.current);
      return from.pop()!;
    }
    this.past.push(this.current);
    this.future = [];
    // A restore here goes back to the review as it began.
    if (url.endsWith("/restore/")) return this.past[0];
    return applyEdit(this.current, this.editFor(url, b), N);
  }

  private editFor(url: string, b: Record<string, unknown>): Edit {
    const cutId = Number(url.match(/cuts\/(\d+)\//)?.[1]);
    const index = Number(url.match(/segments\/(\d+)\//)?.[1]);
    if (url.endsWith("/cuts/")) return { kind: "insert", frame: b.frame as number, tempId: this.nextId++ };
    if (b.frame !== undefined) return { kind: "move", cutId, frame: b.frame as number };
    if (b.fate !== undefined) return { kind: "fate", cutId, fate: b.fate as "accepted" };
    const s = this.current.segments[index];
    return { kind: "label", start: s.start, stop: s.stop, label: b.label as string | null };
  }
}

/** A session over a stand-in server, with what it told the page. */
function open(start: Review = review()) {
  const server = new StandInServer(structuredClone(start));
  const told = { notices: [] as string[], conflicts: [] as { changes: string[]; unsaved: string[] }[], settled: 0 };
  let settle = () => {};
  const view: SessionView = {
    changed: () => {},
    notice: (text) => told.notices.push(text),
    saving: () => {},
    settled: () => {
      told.settled++;
      settle();
    },
    conflict: (changes, unsaved) => {
      told.conflicts.push({ changes, unsaved });
      settle();
    },
  };
  const session = new ReviewSession(3, N, structuredClone(start), view, server.send);
  /** Resolves when the saver has sent everything queued (or gave up on a conflict). */
  const saved = () => new Promise<void>((resolve) => (settle = resolve));
  return { session, server, told, saved };
}

describe("ReviewSession", () => {
  it("test_it_shows_an_edit_at_once_and_saves_it_with_the_servers_version", async () => {
    const { session, server, saved } = open();
    const done = saved();
    session.perform({ kind: "fate", cutId: 2, fate: "deleted" });
    expect(session.review.cuts.find((c) => c.id === 2)!.fate).toBe("deleted");
    await done;
    expect(server.requests).toEqual([{ method: "PATCH", url: "/api/captures/3/review/cuts/2/", body: { fate: "deleted", version: 4 } }]);
    expect(session.review.version).toBe(5);
    expect(session.history.past).toEqual(["delete cut at 500"]);
  });

  it("test_it_asks_the_server_to_undo_and_redo_and_shows_its_answer", async () => {
    const { session, server, told, saved } = open();
    let done = saved();
    session.perform({ kind: "move", cutId: 1, frame: 230 });
    await done;
    done = saved();
    session.undo();
    expect(session.history).toEqual({ past: [], future: ["move cut 200 → 230"] });
    await done;
    expect(server.requests.at(-1)).toEqual({ method: "POST", url: "/api/captures/3/review/undo/", body: { version: 5 } });
    expect(session.review.cuts.find((c) => c.id === 1)).toMatchObject({ frame: 200, fate: "pending" });
    done = saved();
    session.redo();
    await done;
    expect(session.review.cuts.find((c) => c.id === 1)).toMatchObject({ frame: 230, fate: "moved" });
    expect(told.notices).toEqual(["Undo: move cut 200 → 230", "Redo: move cut 200 → 230"]);
  });

  it("test_it_takes_its_undo_history_from_the_servers_log_after_a_reload", () => {
    const { session, told } = open();
    session.undo();
    expect(told.notices).toEqual(["Nothing to undo."]);
    const at = "2026-01-01T10:00:00Z";
    session.readHistory([
      { id: 1, user: "ann", action: "create", cut: null, before: null, after: { candidates: 3 }, created_at: at },
      { id: 2, user: "ann", action: "delete", cut: 2, before: { frame: 500, fate: "pending" }, after: { frame: 500, fate: "deleted" }, created_at: at },
    ]);
    expect(session.history).toEqual({ past: ["delete frame 500: pending → deleted"], future: [] });
  });

  it("test_it_ignores_a_log_asked_for_before_its_last_undo", async () => {
    const { session, saved } = open();
    const at = "2026-01-01T10:00:00Z";
    const log = [
      { id: 1, user: "ann", action: "create", cut: null, before: null, after: { candidates: 3 }, created_at: at },
      { id: 2, user: "ann", action: "delete", cut: 2, before: { frame: 500, fate: "pending" }, after: { frame: 500, fate: "deleted" }, created_at: at },
    ];
    session.readHistory(log);
    const asOf = session.sent; // the page asks for the log now...
    const done = saved();
    session.undo(); // ...and the annotator undoes before it arrives
    await done;
    session.readHistory(log, asOf);
    expect(session.history).toEqual({ past: [], future: ["delete frame 500: pending → deleted"] });
  });

  it("test_it_restores_a_point_of_the_log_as_a_step_undo_takes_back", async () => {
    const { session, server, saved } = open();
    const done = saved();
    session.restore(41, "accept frame 200");
    await done;
    expect(server.requests).toEqual([{ method: "POST", url: "/api/captures/3/reviews/7/restore/", body: { event: 41, version: 4 } }]);
    expect(session.history.past).toEqual(["restore an earlier point"]);
    expect(session.review.version).toBe(5);
  });

  it("test_it_gives_an_inserted_cut_its_server_id_and_keeps_it_selected", async () => {
    const { session, saved } = open();
    const done = saved();
    session.insertAt(650);
    const temp = session.selectedCutId!;
    expect(temp).toBeLessThan(0);
    await done;
    expect(session.selectedCutId).toBe(100);
    expect(session.selectedCut()).toMatchObject({ id: 100, frame: 650, origin: "inserted" });
  });

  it("test_it_shows_the_servers_review_and_lists_the_unsaved_edits_on_a_conflict", async () => {
    const { session, server, told, saved } = open();
    // Another tab deleted cut 3 first: the server is one version ahead.
    server.current = { ...applyEdit(server.current, { kind: "fate", cutId: 3, fate: "deleted" }, N), version: 5 };
    const done = saved();
    session.perform({ kind: "fate", cutId: 1, fate: "accepted" });
    await done;
    expect(told.conflicts).toEqual([{ changes: ["cut at frame 200 is candidate, not accepted", "cut at frame 800 is deleted, not candidate"], unsaved: ["accept cut at 200"] }]);
    expect(session.review.cuts.find((c) => c.id === 1)!.fate).toBe("pending");
    expect(session.history.past).toEqual([]);
  });

  it("test_it_refuses_edits_to_a_submitted_review_without_asking_the_server", async () => {
    const { session, server, told } = open({ ...review(), status: "submitted" });
    expect(session.perform({ kind: "fate", cutId: 1, fate: "accepted" })).toBe(false);
    expect(told.notices).toEqual(["This review was submitted; it is read-only now."]);
    expect(server.requests).toEqual([]);
  });

  it("test_it_shows_another_review_read_only_and_then_the_own_one_again", () => {
    const { session } = open();
    const theirs = { ...review([cut(9, 300)]), annotator: { id: 2, username: "bob" } };
    session.show(theirs);
    expect(session.locked()).toBe("You are viewing bob's review, read-only.");
    expect(session.perform({ kind: "insert", frame: 400, tempId: -9 })).toBe(false);
    session.show(null);
    expect(session.locked()).toBeNull();
    expect(session.review.cuts.map((c) => c.id)).toEqual([1, 2, 3]);
  });

  it("test_it_submits_with_the_version_the_server_last_returned", async () => {
    const { session, server } = open();
    await session.submit();
    expect(server.requests.at(-1)).toEqual({ method: "POST", url: "/api/captures/3/review/submit/", body: { version: 4 } });
    expect(session.locked()).toBe("This review was submitted; it is read-only now.");
  });
});
