import { describe, expect, it } from "vitest";
import type { Adaptation, CaptureSummary } from "../src/api/types";
import { canRedetect } from "../src/captures/list";
import { adaptationLines } from "../src/review/panels";

const zeroShot: Adaptation = { model_version: null, n_takes: null, held_out: null, project_model: null, training: false, training_error: null, training_refused: null, training_skipped: null };
// A model trained before the figure's basis was kept.
const figure = { n_takes: 5, edits_per_cut: 0.3, f1: 0.912, gold: null, shared: null, single: null, annotators: null, true_cuts: null };

describe("adaptation line of the review page", () => {
  it("test_it_says_candidates_are_not_adapted_yet", () => {
    expect(adaptationLines(zeroShot)).toEqual({ line: "Candidates not adapted yet (zero-shot detector).", figure: "", notes: [], failure: "" });
  });

  it("test_it_says_how_many_reviewed_takes_the_candidates_came_from", () => {
    const a = { ...zeroShot, model_version: 3, n_takes: 12, project_model: { version: 3, n_takes: 12, n_cuts: 80, held_out: null } };
    expect(adaptationLines(a)).toEqual({ line: "Candidates adapted from 12 reviewed takes (model v3).", figure: "", notes: [], failure: "" });
    expect(adaptationLines({ ...a, n_takes: 1 }).line).toBe("Candidates adapted from 1 reviewed take (model v3).");
  });

  it("test_it_mentions_a_newer_project_model", () => {
    const a = { ...zeroShot, project_model: { version: 2, n_takes: 5, n_cuts: 30, held_out: null } };
    expect(adaptationLines(a).notes).toEqual(["The project's model is now v2, from 5 reviewed takes."]);
    const withFigure = { ...a, project_model: { ...a.project_model, held_out: figure } };
    expect(adaptationLines(withFigure).notes).toEqual([
      "The project's model is now v2, from 5 reviewed takes; on 5 held-out reviewed takes 0.30 edits per cut, F1 0.91.",
    ]);
  });

  it("test_it_shows_the_models_own_figure_on_held_out_reviewed_takes", () => {
    const a = { ...zeroShot, model_version: 2, n_takes: 5, held_out: figure, project_model: { version: 2, n_takes: 5, n_cuts: 30, held_out: figure } };
    expect(adaptationLines(a).figure).toBe("Learnt from 5 reviewed takes; on 5 held-out reviewed takes 0.30 edits per cut, F1 0.91.");
    expect(adaptationLines({ ...a, held_out: { ...figure, n_takes: 1 } }).figure).toBe(
      "Learnt from 5 reviewed takes; on 1 held-out reviewed take 0.30 edits per cut, F1 0.91.",
    );
  });

  it("test_it_has_no_figure_for_the_zero_shot_detector_or_a_model_without_one", () => {
    expect(adaptationLines({ ...zeroShot, held_out: figure }).figure).toBe("");
    expect(adaptationLines({ ...zeroShot, model_version: 1, n_takes: 2 }).figure).toBe("");
  });

  it("test_it_says_why_the_last_model_was_refused_and_what_is_kept", () => {
    const refused = "refused: on 2 held-out reviewed takes that the current model v1 learnt from it needs 1.00 edits per true cut (F1 0.00), the current model 0.25 edits per true cut (F1 1.00)";
    const a = { ...zeroShot, project_model: { version: 1, n_takes: 2, n_cuts: 8, held_out: null }, model_version: 1, n_takes: 2, training_refused: refused };
    // The project's news for its reviewers and admins, not a failure: drawn neutral.
    expect(adaptationLines(a).notes).toEqual([`Last retraining ${refused}. The project keeps model v1.`]);
    expect(adaptationLines(a).failure).toBe("");
  });

  it("test_it_says_what_the_figure_was_measured_on", () => {
    const basis = { ...figure, gold: 2, shared: 1, single: 2, annotators: 2, true_cuts: 40 };
    const a = { ...zeroShot, model_version: 2, n_takes: 5, held_out: basis };
    expect(adaptationLines(a).figure).toBe(
      "Learnt from 5 reviewed takes; on 5 held-out reviewed takes (2 with a gold version, 1 reviewed by several annotators, 2 reviewed by one annotator alone each (2 annotators)) 0.30 edits per cut, F1 0.91.",
    );
  });

  it("test_it_gives_no_f1_for_one_annotators_reviews_without_a_cut", () => {
    // Issue 48, item 3: a model that proposes nothing, scored on an under-cutter's own
    // reviews, was shown as "F1 1.00".
    const poisoned = { n_takes: 4, edits_per_cut: 0, f1: 1, gold: 0, shared: 0, single: 4, annotators: 1, true_cuts: 0 };
    const a = { ...zeroShot, model_version: 1, n_takes: 4, held_out: poisoned };
    expect(adaptationLines(a).figure).toBe(
      "Learnt from 4 reviewed takes; on 4 held-out reviewed takes (all reviewed by one annotator alone) 0.00 edits per cut, no F1 (those reviews keep no cut).",
    );
  });

  it("test_it_names_the_takes_the_last_training_left_out", () => {
    const a = { ...zeroShot, training_skipped: "capture 3 ('short.bvh') skipped: too short to learn from (3 frames)\ncapture 4 ('x.csv') skipped: too short to learn from (3 frames)" };
    expect(adaptationLines(a).notes).toEqual([
      "Last retraining left out: capture 3 ('short.bvh') skipped: too short to learn from (3 frames); capture 4 ('x.csv') skipped: too short to learn from (3 frames).",
    ]);
  });

  it("test_it_says_why_the_last_training_failed_and_what_is_kept", () => {
    const a = { ...zeroShot, training_error: "training: capture 4 cannot be read." };
    expect(adaptationLines(a).failure).toBe("Last retraining failed: training: capture 4 cannot be read. The project keeps the zero-shot detector.");
    expect(adaptationLines(a).notes).toEqual([]);
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
