// The side panels of the review page, each redrawn whole from the current state.

import type { Adaptation, Cut, HeldOut, Label, Review, ReviewEvent, Segment } from "../api/types";
import { clear, formatDuration, h } from "../ui/dom";
import { eventDetail } from "./events";
import { FATE_TEXT } from "./state";
import { formatTime } from "./timescale";

export function renderLabels(el: HTMLElement, labels: Label[], current: string | null, disabled: boolean, pick: (name: string) => void, proposed: string | null = null): void {
  if (!labels.length) {
    clear(el, h("p", { class: "muted" }, "This project has no labels yet."));
    return;
  }
  const chip = (label: Label) =>
    h(
      "button",
      {
        class: `label-chip${current === label.name ? " current" : ""}${!current && proposed === label.name ? " proposed" : ""}`,
        "data-testid": `label-${label.name}`,
        disabled,
        title: `${label.name}: label the segment under the playhead${label.hotkey ? ` (${label.hotkey})` : ""}`,
        onclick: (e: Event) => {
          (e.currentTarget as HTMLElement).blur();
          pick(label.name);
        },
      },
      h("span", { class: "swatch", style: `background:${label.color}` }),
      h("span", { class: "name" }, label.name),
      label.hotkey ? h("kbd", {}, label.hotkey) : null,
    );
  clear(el, ...labels.map(chip));
}

export function renderSelection(el: HTMLElement, cut: Cut | undefined, segment: Segment | undefined, fps: number): void {
  clear(
    el,
    cut ? cutPanel(cut, fps) : h("div", { class: "muted" }, "No cut selected: click one, or Shift+←/→."),
    segment ? segmentPanel(segment, fps) : null,
  );
}

function cutPanel(cut: Cut, fps: number): HTMLElement {
  return h(
    "div",
    { class: "sel-cut", "data-testid": "selected-cut" },
    h("div", {}, h("b", {}, `Cut at ${cut.frame}`), ` · ${formatTime(cut.frame, fps)}`),
    h("div", { class: `fate fate-${cut.fate}` }, cut.origin === "inserted" ? "inserted" : FATE_TEXT[cut.fate]),
    cut.candidate_frame !== null && cut.candidate_frame !== cut.frame ? h("div", { class: "muted" }, `proposed at ${cut.candidate_frame}`) : null,
    cut.confidence !== null ? h("div", { class: "muted" }, `confidence ${(cut.confidence * 100).toFixed(0)} %`) : null,
  );
}

function segmentPanel(segment: Segment, fps: number): HTMLElement {
  return h(
    "div",
    { class: "sel-seg", "data-testid": "current-segment" },
    h("b", {}, `Segment ${segment.index + 1}`),
    ` · ${segment.start}–${segment.stop} · ${formatDuration((segment.stop - segment.start) / fps)}`,
    h("div", {}, segment.label ? `labelled ${segment.label}` : h("span", { class: "muted" }, "unlabelled")),
    !segment.label && segment.suggested_label ? suggestion(segment, segment.suggested_label) : null,
  );
}

/** A proposal (a frame model's, with its probability) or a library suggestion: not the
 * segment's label until accepted. */
function suggestion(segment: Segment, label: string): HTMLElement {
  const p = segment.proposed_probability;
  if (p === null || p === undefined)
    return h("div", { class: "muted", "data-testid": "suggested-label" }, `suggested: ${label} (S accepts)`);
  return h("div", { class: "proposed-label", "data-testid": "proposed-label" },
    h("i", {}, label), ` proposed, ${percent(p)} (S accepts)`);
}

export const percent = (p: number) => `${Math.round(p * 100)} %`;

/** Cut counts by fate (inserted cuts counted apart) and how much is labelled. */
export function renderStats(el: HTMLElement, review: Review): void {
  const counts: Record<string, number> = { pending: 0, accepted: 0, moved: 0, inserted: 0, deleted: 0 };
  for (const cut of review.cuts) counts[cut.origin === "inserted" && cut.fate !== "deleted" ? "inserted" : cut.fate]++;
  const labelled = review.segments.filter((s) => s.label).length;
  clear(
    el,
    h("div", { class: "stat-grid" }, ...Object.entries(counts).map(([k, v]) => h("div", { class: `stat stat-${k}` }, h("b", {}, v), h("span", {}, k)))),
    h("div", { class: "muted" }, `${labelled} of ${review.segments.length} segments labelled · version ${review.version} · ${review.status.replace("_", " ")}`),
  );
}

/**
 * The audit log, newest first. With `restore`, every entry but the newest offers to bring
 * the review back to how it was right after that entry.
 */
export function renderEvents(el: HTMLElement, events: ReviewEvent[], restore?: (e: ReviewEvent) => void): void {
  const newest = events[events.length - 1];
  const item = (e: ReviewEvent) =>
    h(
      "li",
      { "data-action": e.action, "data-event": String(e.id) },
      h("span", { class: "ev-action" }, actionText(e)),
      h("span", { class: "ev-detail", title: eventDetail(e) }, eventDetail(e)),
      h("time", { datetime: e.created_at, title: e.created_at }, new Date(e.created_at).toLocaleTimeString()),
      restore && e !== newest
        ? h("button", {
            class: "btn btn-ghost ev-restore", "data-testid": `restore-event-${e.id}`, "aria-label": "Restore",
            title: "Restore the review as it was right after this entry (the restore is an entry too: undo takes it back)",
            onclick: (ev: Event) => {
              (ev.currentTarget as HTMLElement).blur();
              restore(e);
            },
          }, "↺")
        : null,
    );
  clear(el, ...events.slice().reverse().map(item));
  if (!events.length) el.append(h("li", { class: "muted" }, "No edits yet."));
}

/** An entry's action in words: a restore the server made for undo or redo says so. */
function actionText(e: ReviewEvent): string {
  const intent = e.action === "restore" ? (e.after as { intent?: string | null } | null)?.intent : null;
  return intent ?? e.action.replace(/_/g, " ");
}

const takes = (n: number) => `${n} reviewed take${n === 1 ? "" : "s"}`;

/**
 * Where the candidates came from — "adapted from 12 reviewed takes" or "not adapted yet" —
 * that model's own figure on held-out reviewed takes, then the project's newer model, a
 * training under way or why its model was refused (news: the server tells reviewers and
 * admins only), and apart, as a failure, why the last training failed.
 */
export function adaptationLines(a: Adaptation | undefined): { line: string; figure: string; notes: string[]; failure: string } {
  if (!a) return { line: "", figure: "", notes: [], failure: "" };
  const adapted = a.model_version !== null && a.n_takes !== null;
  const line = adapted ? `Candidates adapted from ${takes(a.n_takes!)} (model v${a.model_version}).` : "Candidates not adapted yet (zero-shot detector).";
  const figure = adapted && a.held_out ? `Learnt from ${takes(a.n_takes!)}; ${heldOut(a.held_out)}.` : "";
  const notes: string[] = [];
  const project = a.project_model;
  if (project && project.version !== a.model_version) {
    notes.push(`The project's model is now v${project.version}, from ${takes(project.n_takes)}${project.held_out ? `; ${heldOut(project.held_out)}` : ""}.`);
  }
  if (a.training) notes.push("Retraining on the newest reviews…");
  const kept = project ? `model v${project.version}` : "the zero-shot detector";
  if (a.training_refused) notes.push(`Last retraining ${a.training_refused}. The project keeps ${kept}.`);
  if (a.training_skipped) notes.push(`Last retraining left out: ${a.training_skipped.split("\n").join("; ")}.`);
  const failure = a.training_error ? `Last retraining failed: ${a.training_error} The project keeps ${kept}.` : "";
  return { line, figure, notes, failure };
}

/**
 * "on 5 held-out reviewed takes (2 with a gold version, 3 reviewed by one annotator alone)
 * 0.30 edits per cut, F1 0.91": what the figure was measured on, since a figure measured on
 * one annotator's own reviews says how well the model follows that annotator, and an F1 on
 * reviews that keep no cut says nothing.
 */
function heldOut(h: HeldOut): string {
  const f1 = h.true_cuts === 0 ? "no F1 (those reviews keep no cut)" : `F1 ${h.f1.toFixed(2)}`;
  return `on ${h.n_takes} held-out reviewed take${h.n_takes === 1 ? "" : "s"}${basis(h)} ${h.edits_per_cut.toFixed(2)} edits per cut, ${f1}`;
}

/** " (all reviewed by one annotator alone)", " (1 with a gold version, 2 reviewed by several annotators)"… */
function basis(h: HeldOut): string {
  if (h.gold === null || h.shared === null || h.single === null || h.annotators === null) return "";
  const alone = h.annotators === 1 ? "one annotator alone" : `one annotator alone each (${h.annotators} annotators)`;
  if (h.single === h.n_takes) return ` (all reviewed by ${alone})`;
  const parts = [
    h.gold ? `${h.gold} with a gold version` : "",
    h.shared ? `${h.shared} reviewed by several annotators` : "",
    h.single ? `${h.single} reviewed by ${alone}` : "",
  ].filter(Boolean);
  return ` (${parts.join(", ")})`;
}

export function renderAdaptation(el: HTMLElement, a: Adaptation | undefined): void {
  const { line, figure, notes, failure } = adaptationLines(a);
  clear(
    el,
    line ? h("div", { "data-testid": "adaptation-line" }, line) : null,
    figure ? h("div", { class: "muted small", "data-testid": "adaptation-figure" }, figure) : null,
    ...notes.map((note) => h("div", { class: "muted small", "data-testid": "adaptation-note" }, note)),
    failure ? h("div", { class: "error-text small", "data-testid": "adaptation-failure" }, failure) : null,
  );
}
