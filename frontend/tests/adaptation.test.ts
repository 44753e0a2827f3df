import { describe, expect, it } from "vitest";
import type { Adaptation, CaptureSummary } from "../src/api/types";
import { canRedetect } from "../src/captures/list";
import { adaptationLines } from "../src/review/panels";

const zeroShot: Adaptation = { model_version: null, n_takes: null, project_model: null, training: false, training_error: null };

describe("adaptation line of the review page", () => {
  it("test_it_says_candidates_are_not_adapted_yet", () => {
    expect(adaptationLines(zeroShot)).toEqual({ line: "Candidates not adapted yet (zero-shot detector).", notes: [] });
  });

  it("test_it_says_how_many_reviewed_takes_the_candidates_came_from", () => {
    const a = { ...zeroShot, model_version: 3, n_takes: 12, project_model: { version: 3, n_takes: 12, n_cuts: 80 } };
    expect(adaptationLines(a)).toEqual({ line: "Candidates adapted from 12 reviewed takes (model v3).", notes: [] });
    expect(adaptationLines({ ...a, n_takes: 1 }).line).toBe("Candidates adapted from 1 reviewed take (model v3).");
  });

  it("test_it_mentions_a_newer_project_model", () => {
    const a = { ...zeroShot, project_model: { version: 2, n_takes: 5, n_cuts: 30 } };
    expect(adaptationLines(a).notes).toEqual(["The project's model is now v2, from 5 reviewed takes."]);
  });

  it("test_it_says_why_the_last_training_failed_and_what_is_kept", () => {
    const a = { ...zeroShot, training_error: "training: capture 4 cannot be read." };
    expect(adaptationLines(a).notes).toEqual(["Last retraining failed: training: capture 4 cannot be read. The project keeps the zero-shot detector."]);
  });
});

describe("re-detect button", () => {
  const capture = { status: "ready", review_started: false, latest_run: { status: "ready" } } as CaptureSummary;

  it("test_it_is_offered_to_reviewers_and_admins_only", () => {
    expect([canRedetect(capture, "reviewer"), canRedetect(capture, "admin"), canRedetect(capture, "annotator")]).toEqual([true, true, false]);
  });

  it("test_it_is_not_offered_once_someone_started_reviewing_or_while_detecting", () => {
    expect(canRedetect({ ...capture, review_started: true }, "reviewer")).toBe(false);
    expect(canRedetect({ ...capture, latest_run: { ...capture.latest_run!, status: "queued" } }, "reviewer")).toBe(false);
  });
});
