// The agreement summary shown at the top of the adjudication page.

import type { Agreement } from "../library/types";
import { h } from "../ui/dom";

const fmt = (v: number | null | undefined, digits = 2) => (v === null || v === undefined ? "—" : v.toFixed(digits));

export function agreementBox(a: Agreement): HTMLElement {
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
