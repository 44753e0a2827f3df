// The label taxonomy editor of the Team page: add, rename, recolour, set the hotkey,
// move up or down, retire or restore. A retired label stays on the segments that carry it.

import { get, patch, post } from "../api/client";
import type { Label, Project } from "../api/types";
import { clear, h, toast } from "../ui/dom";

const HOTKEYS = ["", "1", "2", "3", "4", "5", "6", "7", "8", "9"];

export function taxonomyEditor(project: Project): HTMLElement {
  let labels = project.labels.slice();
  const list = h("tbody", { "data-testid": "taxonomy" });
  const base = `/api/projects/${project.id}/labels/`;

  const reload = async () => {
    labels = (await get<Project>(`/api/projects/${project.id}/`)).labels;
    draw();
  };
  const change = async (label: Label, fields: Partial<Label>, done: string) => {
    try {
      await patch(`${base}${label.id}/`, fields);
      toast(done);
    } catch (err) {
      toast((err as Error).message, "error");
    }
    await reload();
  };
  const move = async (index: number, by: number) => {
    const order = labels.map((l) => l.id);
    const [id] = order.splice(index, 1);
    order.splice(index + by, 0, id);
    try {
      await post(`${base}order/`, { order });
    } catch (err) {
      toast((err as Error).message, "error");
    }
    await reload();
  };

  const row = (label: Label, index: number) => {
    const name = h("input", { class: "input", value: label.name, "data-testid": `label-name-${label.name}`, "aria-label": "name" });
    const commitName = () => name.value.trim() && name.value.trim() !== label.name && void change(label, { name: name.value.trim() }, `Renamed to ${name.value.trim()}.`);
    name.addEventListener("change", commitName);
    const color = h("input", { type: "color", value: label.color, "data-testid": `label-color-${label.name}`, "aria-label": "colour" });
    color.addEventListener("change", () => void change(label, { color: color.value }, `${label.name}: new colour.`));
    const hotkey = h("select", { class: "select select-small", "data-testid": `label-hotkey-${label.name}`, "aria-label": "hotkey", disabled: label.retired }, ...HOTKEYS.map((k) => h("option", { value: k, selected: (label.hotkey ?? "") === k }, k || "—")));
    hotkey.addEventListener("change", () => void change(label, { hotkey: hotkey.value || null }, hotkey.value ? `${label.name} answers to ${hotkey.value}.` : `${label.name} has no hotkey.`));
    return h(
      "tr",
      { class: label.retired ? "retired" : "", "data-testid": `label-row-${label.name}` },
      h("td", {}, color),
      h("td", {}, name),
      h("td", {}, hotkey),
      h("td", {},
        h("button", { class: "btn btn-small", title: "Move up", disabled: index === 0, onclick: () => void move(index, -1) }, "↑"),
        h("button", { class: "btn btn-small", title: "Move down", "data-testid": `label-down-${label.name}`, disabled: index === labels.length - 1, onclick: () => void move(index, 1) }, "↓")),
      h("td", {}, h("button", { class: "btn btn-small", "data-testid": `label-retire-${label.name}`, onclick: () => void change(label, { retired: !label.retired }, label.retired ? `${label.name} is back in use.` : `${label.name} is retired.`) }, label.retired ? "Restore" : "Retire")),
    );
  };

  const draw = () => {
    clear(list, ...labels.map(row));
    if (!labels.length) list.append(h("tr", {}, h("td", { colspan: 5, class: "muted" }, "No labels yet.")));
  };

  const newName = h("input", { class: "input", placeholder: "new label", "data-testid": "new-label-name" });
  const newColor = h("input", { type: "color", value: "#4f8cc9", "data-testid": "new-label-color" });
  const form = h("form", { class: "inline-form", "data-testid": "new-label" }, newColor, newName, h("button", { class: "btn btn-primary", type: "submit" }, "Add label"));
  form.addEventListener("submit", (e) => {
    e.preventDefault();
    const name = newName.value.trim();
    if (!name) return;
    post(base, { name, color: newColor.value, hotkey: null })
      .then(() => {
        newName.value = "";
        toast(`Added ${name}.`);
        return reload();
      })
      .catch((err: Error) => toast(err.message, "error"));
  });

  draw();
  return h(
    "section",
    { class: "team-section" },
    h("h2", {}, "Labels"),
    h("p", { class: "muted" }, "Hotkeys 1–9 apply a label in the review page; with more labels, press / there for the label palette. A retired label stays on segments that have it but is no longer offered."),
    h("table", { class: "captures taxonomy" }, h("thead", {}, h("tr", {}, ...["Colour", "Name", "Hotkey", "Order", ""].map((t) => h("th", {}, t)))), list),
    form,
  );
}
