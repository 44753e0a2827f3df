// Adjudication (reviewers): every annotator's cuts and labels overlaid on one time axis,
// the agreement between them, and the gold version being made — start from one
// annotator's version, then split, move, merge and relabel segments, and save.

import { ApiError, api, get } from "../api/client";
import { clear, h, toast } from "../ui/dom";
import { addCut, type Draft, fromSpans, moveCut, removeCut, sameDraft, setLabel, toSpans } from "./gold";
import type { Adjudication, Agreement, Span } from "./types";
import { topbar } from "./nav";
import { ClipPreview } from "./preview";

const fmt = (v: number | null | undefined, digits = 2) => (v === null || v === undefined ? "—" : v.toFixed(digits));

export async function renderAdjudication(root: HTMLElement, captureId: number): Promise<() => void> {
  let data = await get<Adjudication>(`/api/captures/${captureId}/adjudication/`);
  const n = data.capture.n_frames;
  const colors = new Map(data.labels.map((l) => [l.name, l.color]));
  let draft: Draft = data.gold ? fromSpans(data.gold.segments) : { cuts: [], labels: [null] };
  let saved: Draft | null = data.gold ? fromSpans(data.gold.segments) : null;
  let source: number | null = data.gold?.source_review ?? null;
  let selected = 0;

  const tracks = h("div", { class: "adj-tracks", "data-testid": "adj-tracks" });
  const editor = h("div", { class: "adj-editor", "data-testid": "gold-editor" });
  const status = h("span", { class: "muted", "data-testid": "gold-status" });
  const saveButton = h("button", { class: "btn btn-primary", "data-testid": "save-gold", onclick: () => void save() }, "Save gold version");
  const seconds = (frame: number) => `${(frame / data.capture.fps).toFixed(2)} s`;

  const preview = h("aside", { class: "lib-preview", "data-testid": "preview" }, h("p", { class: "muted" }, "Click a segment on any track to play it here."));
  const player = new ClipPreview(preview);
  const play = (who: string, s: Span) =>
    void player.play(captureId, s.start, s.stop, `${who} · ${s.label ?? "unlabelled"} · frames ${s.start}–${s.stop}`, `${who}:${s.start}`);

  const track = (spans: Span[], testid: string, onPick: (i: number) => void, selectable = false) =>
    h(
      "div",
      { class: "adj-track", "data-testid": testid },
      ...spans.map((s, i) =>
        h(
          "div",
          {
            class: `adj-seg${selectable && i === selected ? " selected" : ""}${s.label ? "" : " unlabelled"}`,
            style: `left:${(s.start / n) * 100}%;width:${((s.stop - s.start) / n) * 100}%;background:${s.label ? colors.get(s.label) ?? "#888" : "transparent"}`,
            title: `${s.label ?? "unlabelled"} · ${s.start}–${s.stop} (${seconds(s.stop - s.start)})`,
            "data-testid": `${testid}-seg-${i}`,
            onclick: () => onPick(i),
          },
          h("span", {}, s.label ?? ""),
        ),
      ),
    );

  function drawTracks(): void {
    clear(
      tracks,
      ...data.reviews.map((r) =>
        h(
          "div",
          { class: "adj-row" },
          h("div", { class: "adj-who" }, h("b", {}, r.annotator.username), h("span", { class: "muted small" }, ` ${r.status.replace("_", " ")}, ${r.cuts.length} cuts`)),
          track(r.segments, `track-${r.annotator.username}`, (i) => play(r.annotator.username, r.segments[i])),
          h("button", { class: "btn", "data-testid": `use-${r.annotator.username}`, onclick: () => use(r.id, r.segments) }, "Start gold from this"),
        ),
      ),
      h(
        "div",
        { class: "adj-row adj-gold" },
        h("div", { class: "adj-who" }, h("b", {}, "Gold"), h("span", { class: "muted small" }, data.gold ? ` v${data.gold.version} by ${data.gold.adjudicator ?? "?"}` : " not saved yet")),
        track(
          toSpans(draft, n),
          "track-gold",
          (i) => {
            selected = i;
            redraw();
            play("gold", toSpans(draft, n)[i]);
          },
          true,
        ),
        status,
      ),
    );
  }

  function drawEditor(): void {
    const spans = toSpans(draft, n);
    selected = Math.min(selected, spans.length - 1);
    const s = spans[selected];
    const labelSelect = h(
      "select",
      { class: "select", "data-testid": "gold-label", "aria-label": "label of the selected segment" },
      h("option", { value: "", selected: s.label === null }, "(unlabelled)"),
      ...data.labels.map((l) => h("option", { value: l.name, selected: s.label === l.name }, l.name)),
    );
    labelSelect.addEventListener("change", () => update(setLabel(draft, selected, labelSelect.value || null)));
    const splitAt = h("input", { class: "input small-input", type: "number", min: s.start + 1, max: s.stop - 1, value: Math.round((s.start + s.stop) / 2), "data-testid": "split-frame" });
    const cutRows = draft.cuts.map((c, i) => {
      const input = h("input", { class: "input small-input", type: "number", value: c, "data-testid": `gold-cut-${i}`, "aria-label": `cut ${i + 1} frame` });
      input.addEventListener("change", () => update(moveCut(draft, i, Number(input.value), n)));
      return h("li", {}, input, h("span", { class: "muted small" }, ` ${seconds(c)} `), h("button", { class: "btn btn-ghost", "data-testid": `remove-cut-${i}`, title: "Remove this cut (merge its segments)", onclick: () => update(removeCut(draft, i)) }, "×"));
    });
    clear(
      editor,
      h("h3", {}, `Segment ${selected + 1} of ${spans.length}: frames ${s.start}–${s.stop}`),
      h("div", { class: "filters" }, labelSelect, splitAt, h("button", { class: "btn", "data-testid": "split", onclick: () => update(addCut(draft, Number(splitAt.value), n)) }, "Split here")),
      h("h3", {}, "Cuts"),
      cutRows.length ? h("ol", { class: "adj-cuts" }, ...cutRows) : h("p", { class: "muted" }, "No cuts: one segment covers the take."),
    );
  }

  function redraw(): void {
    drawTracks();
    drawEditor();
    const dirty = !saved || !sameDraft(draft, saved);
    status.textContent = dirty ? "Unsaved changes" : "Saved";
    saveButton.toggleAttribute("disabled", !dirty);
  }

  function update(next: Draft): void {
    draft = next;
    redraw();
  }

  function use(reviewId: number, spans: Span[]): void {
    source = reviewId;
    selected = 0;
    update(fromSpans(spans));
  }

  async function save(): Promise<void> {
    const body = { cuts: draft.cuts, labels: draft.labels, version: data.gold?.version ?? 0, source_review: source };
    try {
      data = await api<Adjudication>("PUT", `/api/captures/${captureId}/adjudication/`, body);
      saved = fromSpans(data.gold!.segments);
      draft = saved;
      toast(`Gold version ${data.gold!.version} saved.`);
      summary.replaceWith((summary = agreementBox(data.agreement)));
      redraw();
    } catch (err) {
      const message = err instanceof ApiError && err.status === 409 ? "Someone saved the gold version meanwhile; reload to see it." : (err as Error).message;
      toast(message, "error");
    }
  }

  let summary = agreementBox(data.agreement);
  clear(
    root,
    h(
      "div",
      { class: "list-page" },
      topbar([["Captures", "/"], [data.capture.name, `/captures/${captureId}/`], ["Adjudication", null]], data.capture.project),
      h(
        "main",
        { class: "list-main" },
        h("h1", { class: "page-title", "data-testid": "adj-title" }, `Adjudicate ${data.capture.name}`),
        summary,
        tracks,
        h("div", { class: "adj-actions" }, saveButton),
        h("div", { class: "lib-layout" }, editor, preview),
      ),
    ),
  );
  redraw();
  return () => player.stop();
}

function agreementBox(a: Agreement): HTMLElement {
  const method = a.labels.method === "cohen_kappa" ? "Cohen's κ" : a.labels.method === "krippendorff_alpha" ? "Krippendorff's α" : "labels";
  return h(
    "section",
    { class: "adj-agreement", "data-testid": "agreement" },
    h(
      "div",
      { class: "stat-grid" },
      h("div", { class: "stat" }, h("b", {}, String(a.n_reviews)), h("span", {}, "submitted reviews")),
      h("div", { class: "stat" }, h("b", { "data-testid": "agreement-f1" }, fmt(a.boundary_f1)), h("span", {}, `boundary F1 (±${a.tolerance_s} s)`)),
      h("div", { class: "stat" }, h("b", { "data-testid": "agreement-labels" }, fmt(a.labels.value)), h("span", {}, method)),
    ),
    a.pairs.length
      ? h(
          "table",
          { class: "captures compact" },
          h("thead", {}, h("tr", {}, ...["Pair", "F1", "Precision", "Recall", "κ"].map((t) => h("th", {}, t)))),
          h("tbody", {}, ...a.pairs.map((p) => h("tr", {}, h("td", {}, `${p.a.annotator} · ${p.b.annotator}`), h("td", { class: "num" }, fmt(p.f1)), h("td", { class: "num" }, fmt(p.precision)), h("td", { class: "num" }, fmt(p.recall)), h("td", { class: "num" }, fmt(p.kappa))))),
        )
      : h("p", { class: "muted" }, "Agreement needs two submitted reviews."),
    a.per_label.length ? h("p", { class: "muted small" }, "Overlap per label: ", a.per_label.map((l) => `${l.label} ${fmt(l.overlap)}`).join(" · ")) : null,
  );
}
