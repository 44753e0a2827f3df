// The label palette: with more labels than number keys, "/" opens a list filtered as you
// type (by name start first, then anywhere); ↑/↓ move, Enter applies, Escape closes.

import type { LabelChoice } from "../api/types";
import { clear, h } from "../ui/dom";

export function filterLabels<L extends LabelChoice>(labels: L[], text: string): L[] {
  const q = text.trim().toLowerCase();
  if (!q) return labels;
  const starts = labels.filter((l) => l.name.toLowerCase().startsWith(q));
  const contains = labels.filter((l) => !starts.includes(l) && l.name.toLowerCase().includes(q));
  return [...starts, ...contains];
}

export function openPalette(labels: LabelChoice[], pick: (name: string) => void): void {
  let shown = labels;
  let index = 0;
  const input = h("input", { class: "input palette-input", placeholder: "Type to filter labels…", "data-testid": "palette-input", "aria-label": "filter labels" });
  const list = h("ul", { class: "palette-list", "data-testid": "palette-list" });
  const close = () => {
    backdrop.remove();
  };
  const draw = () => {
    clear(
      list,
      ...shown.map((l, i) =>
        h(
          "li",
          { class: i === index ? "current" : "", "data-testid": `palette-${l.name}`, onmousedown: (e: Event) => { e.preventDefault(); close(); pick(l.name); } },
          h("span", { class: "swatch", style: `background:${l.color}` }),
          l.name,
          l.hotkey ? h("kbd", {}, l.hotkey) : null,
        ),
      ),
    );
    if (!shown.length) list.append(h("li", { class: "muted" }, "No label matches."));
  };
  input.addEventListener("input", () => {
    shown = filterLabels(labels, input.value);
    index = 0;
    draw();
  });
  input.addEventListener("keydown", (e) => {
    e.stopPropagation();
    if (e.key === "Escape") close();
    else if (e.key === "ArrowDown" || e.key === "ArrowUp") {
      e.preventDefault();
      index = Math.max(0, Math.min(shown.length - 1, index + (e.key === "ArrowDown" ? 1 : -1)));
      draw();
    } else if (e.key === "Enter" && shown[index]) {
      e.preventDefault();
      close();
      pick(shown[index].name);
    }
  });
  const backdrop = h("div", { class: "modal-backdrop palette", "data-testid": "palette", onclick: (e: Event) => e.target === backdrop && close() }, h("div", { class: "modal" }, input, list));
  document.body.append(backdrop);
  draw();
  input.focus();
}
