// Annotations as files for the tools around Cutroom (CSV, ELAN .eaf, Label Studio JSON):
// a menu that downloads one capture's review or gold version, or a library query's
// segments, in the chosen format. Errors (no review yet, a query too large) come back as
// the server's sentence in a toast, not as a page of JSON.

import { h } from "../ui/dom";
import { downloadWithProgress } from "./download";

export const ANNOTATION_FORMATS: [string, string][] = [["csv", "CSV"], ["eaf", "ELAN (.eaf)"], ["labelstudio", "Label Studio JSON"]];

/** A select whose choice downloads `href(format)`; `what` names it in the progress line. */
export function annotationExportMenu(href: (format: string) => string, what: string, title: string, testId: string): HTMLSelectElement {
  const select = h(
    "select",
    { class: "select", title, "aria-label": title, "data-testid": testId },
    h("option", { value: "" }, "Export annotations…"),
    ...ANNOTATION_FORMATS.map(([value, name]) => h("option", { value }, name)),
  ) as HTMLSelectElement;
  select.addEventListener("change", () => {
    const format = select.value;
    select.value = "";
    select.blur();
    if (format) void downloadWithProgress(href(format), `${what} as ${format}`, `annotations.${format === "labelstudio" ? "json" : format}`);
  });
  return select;
}

/** The export of one capture's annotations: `source` is mine, gold, all or a review id. */
export function captureAnnotationsUrl(captureId: number, format: string, source = "mine"): string {
  return `/api/captures/${captureId}/annotations/export.${format}?source=${encodeURIComponent(source)}`;
}
