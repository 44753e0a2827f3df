// The segment attribute editor of the Team page (admins): add an attribute (a choice with
// its options, free text, or yes/no), rename it, change its options or hotkey, delete it.
// The server refuses a change that would drop values segments carry, and says how many.

import { api, get, patch, post } from "../api/client";
import type { Project, SegmentAttribute } from "../api/types";
import { ATTRIBUTE_KEYS } from "../review/keymap";
import { clear, h, toast } from "../ui/dom";

const KINDS: [SegmentAttribute["kind"], string][] = [["choice", "choice"], ["text", "free text"], ["boolean", "yes / no"]];

/** "a, b ,c" -> ["a", "b", "c"]. */
export function parseOptions(text: string): string[] {
  return text.split(",").map((o) => o.trim()).filter(Boolean);
}

export function attributeEditor(project: Project): HTMLElement {
  const base = `/api/projects/${project.id}/attributes/`;
  const list = h("tbody", { "data-testid": "attribute-schema" });
  let attributes: SegmentAttribute[] = [];

  const reload = async () => {
    attributes = await get<SegmentAttribute[]>(base);
    draw();
  };
  const run = async (action: () => Promise<unknown>, done: string) => {
    try {
      await action();
      toast(done);
    } catch (err) {
      toast((err as Error).message, "error");
    }
    await reload();
  };
  const hotkeys = (value: string | null | undefined, testid: string) =>
    h("select", { class: "select select-small", "data-testid": testid, "aria-label": "hotkey" },
      ...["", ...ATTRIBUTE_KEYS].map((k) => h("option", { value: k, selected: (value ?? "") === k }, k ? k.toUpperCase() : "—")));

  const row = (a: SegmentAttribute) => {
    const name = h("input", { class: "input", value: a.name, "data-testid": `attribute-name-${a.name}`, "aria-label": "name" });
    name.addEventListener("change", () => void run(() => patch(`${base}${a.id}/`, { name: name.value.trim() }), `Renamed to ${name.value.trim()}.`));
    const options = h("input", { class: "input", value: (a.options ?? []).join(", "), disabled: a.kind !== "choice", "data-testid": `attribute-options-${a.name}`, "aria-label": "options" });
    options.addEventListener("change", () => void run(() => patch(`${base}${a.id}/`, { options: parseOptions(options.value) }), `${a.name}: options saved.`));
    const key = hotkeys(a.hotkey, `attribute-hotkey-${a.name}`);
    key.addEventListener("change", () => void run(() => patch(`${base}${a.id}/`, { hotkey: key.value || null }), key.value ? `${a.name} answers to ${key.value.toUpperCase()}.` : `${a.name} has no hotkey.`));
    const remove = h("button", { class: "btn btn-small", "data-testid": `attribute-delete-${a.name}`, title: a.in_use ? `Set on ${a.in_use} segment(s): clear it there first` : "Delete" }, "Delete");
    remove.addEventListener("click", () => void run(() => api("DELETE", `${base}${a.id}/`), `Deleted ${a.name}.`));
    return h("tr", { "data-testid": `attribute-row-${a.name}` },
      h("td", {}, name), h("td", {}, KINDS.find(([k]) => k === a.kind)?.[1] ?? a.kind), h("td", {}, options), h("td", {}, key),
      h("td", { class: "muted" }, String(a.in_use ?? 0)), h("td", {}, remove));
  };
  const draw = () => {
    clear(list, ...attributes.map(row));
    if (!attributes.length) list.append(h("tr", {}, h("td", { colspan: 6, class: "muted" }, "No attributes yet.")));
  };

  const newName = h("input", { class: "input", placeholder: "new attribute (e.g. quality)", "data-testid": "new-attribute-name" });
  const newKind = h("select", { class: "select", "data-testid": "new-attribute-kind" }, ...KINDS.map(([k, t]) => h("option", { value: k }, t)));
  const newOptions = h("input", { class: "input", placeholder: "options, comma-separated (a choice)", "data-testid": "new-attribute-options" });
  const newKey = hotkeys(null, "new-attribute-hotkey");
  const form = h("form", { class: "inline-form", "data-testid": "new-attribute" }, newName, newKind, newOptions, newKey, h("button", { class: "btn btn-primary", type: "submit", "data-testid": "add-attribute" }, "Add attribute"));
  form.addEventListener("submit", (e) => {
    e.preventDefault();
    const body = { name: newName.value.trim(), kind: newKind.value, options: newKind.value === "choice" ? parseOptions(newOptions.value) : [], hotkey: newKey.value || null };
    void run(async () => {
      await post(base, body);
      newName.value = newOptions.value = "";
    }, `Added ${body.name}.`);
  });

  void reload();
  return h(
    "section",
    { class: "team-section" },
    h("h2", {}, "Segment attributes"),
    h("p", { class: "muted" }, "What a segment carries beside its label. On the review page an attribute's letter sets it on the segment under the playhead (a choice steps through its options). An attribute or an option that segments carry cannot be deleted: the values stay readable."),
    h("table", { class: "captures taxonomy" }, h("thead", {}, h("tr", {}, ...["Name", "Kind", "Options", "Hotkey", "Segments", ""].map((t) => h("th", {}, t)))), list),
    form,
  );
}
