// Importing existing annotations, into the own review (the review page) or the gold version
// (the adjudication page): a file, then the ELAN tier or Label Studio annotation to take,
// then a project label for every label the project lacks. The server reads the file (POST …/annotations/
// inspect/, which writes nothing) and imports it (…/import/) as one step of the review's
// history; the page shows the review it answers with.

import { api, ApiError } from "../api/client";
import type { components } from "../api/schema";
import { clear, h } from "../ui/dom";

type Inspection = components["schemas"]["Inspection"];
export type Imported = components["schemas"]["Imported"];

export interface ImportTarget {
  captureId: number;
  /** The own review (annotators, everyone) or the gold version (reviewers and admins). */
  into: "review" | "gold";
  /** The version the import is based on: the review's as the page last saved it, or the
   * gold version shown (0 for none). */
  version(): number;
  /** The server's answer: the review or the gold version as imported. */
  imported(answer: Imported, summary: string): void;
}

const INTROS = {
  review: "Your review becomes the file's segments, as one step you can undo.",
  gold: "The gold version becomes the file's segments (it needs a submitted review, as any gold version).",
};

/** Open the import dialog; resolves when it closes (imported or not). */
export function openImportDialog(target: ImportTarget): Promise<void> {
  return new Promise((resolve) => new ImportDialog(target, resolve).open());
}

class ImportDialog {
  private file: File | null = null;
  private inspection: Inspection | null = null;
  /** How many times the file was read: only the answer to the latest reading is shown. */
  private asked = 0;
  private readonly mapping = new Map<string, string>();
  private readonly fileInput = h("input", { type: "file", accept: ".csv,.tsv,.txt,.eaf,.json", "data-testid": "import-file" }) as HTMLInputElement;
  private readonly source = h("select", { class: "input", "data-testid": "import-source" }) as HTMLSelectElement;
  private readonly unit = h("select", { class: "input", "data-testid": "import-unit" }, h("option", { value: "seconds" }, "seconds"), h("option", { value: "frames" }, "frames")) as HTMLSelectElement;
  private readonly details = h("div", { class: "import-details", "data-testid": "import-details" });
  private readonly error = h("p", { class: "error-text", "data-testid": "import-error", hidden: true });
  private readonly ok = h("button", { class: "btn btn-primary", disabled: true, "data-testid": "import-ok", onclick: () => void this.submit() }, "Import") as HTMLButtonElement;
  private readonly backdrop: HTMLElement;
  private readonly onKey = (e: KeyboardEvent) => {
    if (e.key === "Escape") this.close();
    e.stopPropagation(); // the review page's keys are not for this dialog
  };

  constructor(
    private readonly target: ImportTarget,
    private readonly done: () => void,
  ) {
    this.fileInput.addEventListener("change", () => {
      this.file = this.fileInput.files?.[0] ?? null;
      this.source.replaceChildren();
      void this.inspect();
    });
    this.source.addEventListener("change", () => void this.inspect());
    this.unit.addEventListener("change", () => void this.inspect());
    const cancel = h("button", { class: "btn", "data-testid": "import-cancel", onclick: () => this.close() }, "Cancel");
    this.backdrop = h(
      "div",
      { class: "modal-backdrop", role: "dialog", "aria-modal": "true", "aria-label": "Import annotations" },
      h(
        "div",
        { class: "modal import-dialog" },
        h("h2", {}, target.into === "gold" ? "Import annotations into gold" : "Import annotations"),
        h(
          "div",
          { class: "modal-body" },
          h("p", { class: "muted" }, `A CSV (take, start, end, label), an ELAN .eaf file or a Label Studio JSON export. ${INTROS[target.into]}`),
          h("label", { class: "field" }, "File", this.fileInput),
          this.details,
          this.error,
        ),
        h("div", { class: "modal-actions" }, cancel, this.ok),
      ),
    );
  }

  open(): void {
    document.addEventListener("keydown", this.onKey, true);
    document.body.append(this.backdrop);
    this.fileInput.focus();
  }

  private close(): void {
    document.removeEventListener("keydown", this.onKey, true);
    this.backdrop.remove();
    this.done();
  }

  private form(): FormData {
    const data = new FormData();
    if (this.file) data.append("file", this.file);
    if (this.source.value) data.append("source", this.source.value);
    data.append("unit", this.unit.value);
    data.append("target", this.target.into);
    return data;
  }

  private showError(message: string | null): void {
    this.error.textContent = message ?? "";
    this.error.hidden = !message;
  }

  private async inspect(): Promise<void> {
    this.inspection = null;
    this.ok.disabled = true;
    this.showError(null);
    clear(this.details);
    if (!this.file) return;
    // A tier chosen while the file's first reading is on its way: that answer is stale.
    const ask = ++this.asked;
    let found: Inspection;
    try {
      found = await api<Inspection>("POST", `/api/captures/${this.target.captureId}/annotations/inspect/`, this.form());
    } catch (err) {
      if (ask === this.asked) this.showError(err instanceof Error ? err.message : String(err));
      return;
    }
    if (ask !== this.asked) return;
    this.inspection = found;
    this.render(found);
  }

  private render(found: Inspection): void {
    const parts: HTMLElement[] = [];
    if (found.sources.length > 1 || found.format === "eaf") {
      if (!this.source.options.length) {
        this.source.append(...found.sources.map((name) => h("option", { value: name }, name)));
        this.source.value = found.source ?? "";
        if (!found.chosen && found.sources.length) {
          // Several tiers and none chosen yet: the first is shown until the user picks.
          this.source.value = found.sources[0];
          void this.inspect();
        }
      }
      parts.push(h("label", { class: "field" }, found.format === "eaf" ? "Tier" : found.format === "labelstudio" ? "Annotation" : "Annotator", this.source));
    }
    if (found.format === "labelstudio") parts.push(h("label", { class: "field" }, "Start and end count", this.unit));
    if (found.chosen) {
      const labelled = found.segments.filter((s) => s.label).length;
      parts.push(h("p", { "data-testid": "import-summary" }, `${found.segments.length} segment${found.segments.length === 1 ? "" : "s"} (${labelled} labelled) from ${found.file}.`));
      if (found.other_takes) parts.push(h("p", { class: "muted", "data-testid": "import-other-takes" }, `${found.other_takes} annotation${found.other_takes === 1 ? " is" : "s are"} about other takes and left out.`));
      parts.push(...this.mappingRows(found));
    }
    clear(this.details, ...parts);
    this.updateOk();
  }

  /** One row per label the project does not have: a project label to take instead. */
  private mappingRows(found: Inspection): HTMLElement[] {
    const unknown = found.labels.filter((l) => !l.known);
    if (!unknown.length) return [];
    const rows = unknown.map((label) => {
      if (!this.mapping.has(label.name) && label.suggestion) this.mapping.set(label.name, label.suggestion);
      const select = h(
        "select",
        { class: "input", "data-testid": "import-map", "data-label": label.name },
        h("option", { value: "" }, "— choose a label —"),
        ...found.project_labels.map((name) => h("option", { value: name }, name)),
      ) as HTMLSelectElement;
      select.value = this.mapping.get(label.name) ?? "";
      select.addEventListener("change", () => {
        if (select.value) this.mapping.set(label.name, select.value);
        else this.mapping.delete(label.name);
        this.updateOk();
      });
      return h("tr", {}, h("td", {}, `“${label.name}” (${label.count})`), h("td", {}, "→"), h("td", {}, select));
    });
    return [
      h("p", { "data-testid": "import-unknown" }, `${unknown.length} label${unknown.length === 1 ? " is" : "s are"} not in this project. Choose a project label for each — an import creates no labels.`),
      h("table", { class: "import-mapping" }, h("tbody", {}, ...rows)),
    ];
  }

  private unmapped(): string[] {
    return (this.inspection?.labels ?? []).filter((l) => !l.known && !this.mapping.get(l.name)).map((l) => l.name);
  }

  private updateOk(): void {
    this.ok.disabled = !this.inspection?.chosen || this.unmapped().length > 0;
  }

  private async submit(): Promise<void> {
    const found = this.inspection;
    if (!found || this.ok.disabled) return;
    const data = this.form();
    const used = Object.fromEntries([...this.mapping].filter(([name]) => found.labels.some((l) => l.name === name && !l.known)));
    data.append("mapping", JSON.stringify(used));
    data.append("version", String(this.target.version()));
    this.ok.disabled = true;
    try {
      const answer = await api<Imported>("POST", `/api/captures/${this.target.captureId}/annotations/import/`, data);
      this.target.imported(answer, `Imported ${found.segments.length} segments from ${found.file}.`);
      this.close();
    } catch (err) {
      this.showError(err instanceof ApiError || err instanceof Error ? err.message : String(err));
      this.updateOk();
    }
  }
}
