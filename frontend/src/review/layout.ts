// The review page's frame: top bar, 3D stage with its read-outs, side panels, transport
// bar and the timeline's container. Only structure lives here; page.ts fills it in.

import type { Me, ReadyCapture } from "../api/types";
import { SPEEDS } from "../player/clock";
import { clip, formatDuration, h } from "../ui/dom";
import { accountLinks, appLinks } from "../ui/appnav";
import { icon } from "../ui/icons";
import { annotationExportMenu, captureAnnotationsUrl } from "../library/annotationExport";
import type { Command } from "./keymap";

export interface LayoutActions {
  command(c: Command): void;
  submit(): void;
  submitNext(): void;
  help(): void;
  follow(): void;
  speed(value: number): void;
  zoom(factor: number): void;
  importAnnotations(): void;
}

export type Elements = Record<string, HTMLElement>;

export function buildLayout(capture: ReadyCapture, me: Me, actions: LayoutActions): { root: HTMLElement; el: Elements } {
  const el: Elements = {};
  const button = buttonMaker(el);
  const root = h(
    "div",
    { class: "review-page" },
    topbar(capture, me, el, button, actions),
    (el.banner = h("div", { class: "readonly-banner", hidden: true, "data-testid": "readonly-banner" })),
    h("div", { class: "workspace" }, stage(el), side(el)),
    transport(el, button, actions),
    (el.timeline = h("div", { class: "timeline", "data-testid": "timeline" })),
  );
  return { root, el };
}

type ButtonMaker = (id: string, content: string | Node, title: string, action: () => void, extra?: string) => HTMLElement;

function buttonMaker(el: Elements): ButtonMaker {
  return (id, content, title, action, extra = "") =>
    (el[id] = h(
      "button",
      {
        class: `btn ${extra}`, title, "data-testid": id,
        onclick: (e: Event) => {
          // Keys belong to the editor, not to the last button clicked (Space would click it again).
          (e.currentTarget as HTMLElement).blur();
          action();
        },
      },
      content,
    ));
}

function topbar(c: ReadyCapture, me: Me, el: Elements, button: ButtonMaker, actions: LayoutActions): HTMLElement {
  const duration = formatDuration(c.duration ?? c.n_frames / c.fps);
  const facts = `${c.n_frames.toLocaleString()} frames · ${c.fps} fps · ${duration} · ${c.format.toUpperCase()}`;
  return h(
    "header",
    { class: "topbar" },
    h("a", { class: "brand", href: "/" }, "Cutroom"),
    h("nav", { class: "crumbs" }, h("a", { href: "/" }, "Captures"), h("span", {}, "/"), clip(c.name, { class: "current", "data-testid": "capture-name" })),
    h("span", { class: "meta", title: facts }, facts),
    h("span", { class: "spacer" }),
    (el.reviewPicker = h("span", { class: "review-picker" })),
    (el.saveState = h("span", { class: "save-state", "data-testid": "save-state" }, "Saved")),
    button("import-annotations", "Import…", "Import segments from a CSV, ELAN or Label Studio file into your review", actions.importAnnotations),
    annotationExportMenu((f) => captureAnnotationsUrl(c.id, f), "your review", "Download your review's segments for ELAN, Label Studio or a spreadsheet", "export-annotations"),
    button("submit", "Submit review", "Mark this review finished; it can no longer be edited", actions.submit, "btn-primary"),
    button("submit-next", "Submit & next", "Submit, then open the oldest open capture of your queue", actions.submitNext),
    ...appLinks(c.project, me.projects.find((p) => p.id === c.project)?.role ?? null),
    button("help-button", "?", "Keyboard shortcuts (?)", actions.help, "btn-ghost"),
    ...accountLinks(me.username),
  );
}

function stage(el: Elements): HTMLElement {
  el.viewport = h("div", { class: "viewport", "data-testid": "viewport" });
  el.loadingBar = h("div", { class: "hud-loading-bar" });
  el.loading = h("div", { class: "hud-loading", "data-testid": "frames-loading" }, el.loadingBar);
  const hud = h(
    "div",
    { class: "hud" },
    (el.hudFrame = h("div", { class: "hud-frame", "data-testid": "hud-frame" })),
    (el.hudTime = h("div", { class: "hud-time", "data-testid": "hud-time" })),
    (el.hudState = h("div", { class: "hud-state", "data-testid": "hud-state" })),
  );
  return h("div", { class: "stage" }, el.viewport, hud, el.loading);
}

function side(el: Elements): HTMLElement {
  return h(
    "aside",
    { class: "side" },
    h("section", {}, h("h3", {}, "Labels"), (el.labels = h("div", { class: "label-list", "data-testid": "labels" }))),
    h("section", {}, h("h3", {}, "Selection"), (el.selection = h("div", { class: "selection", "data-testid": "selection" }))),
    (el.attributesSection = h("section", { hidden: true }, h("h3", {}, "Attributes"), (el.attributes = h("div", { class: "attributes", "data-testid": "attributes" })))),
    h("section", {}, h("h3", {}, "Comments"), (el.comments = h("div", { class: "comments", "data-testid": "comments" }))),
    h(
      "section",
      {},
      h("h3", {}, "Review"),
      (el.adaptation = h("div", { class: "adaptation", "data-testid": "adaptation" })),
      (el.stats = h("div", { class: "stats", "data-testid": "stats" })),
    ),
    h("section", { class: "grow" }, (el.eventsTitle = h("h3", {}, "Activity")), (el.events = h("ol", { class: "events", "data-testid": "events" }))),
  );
}

function transport(el: Elements, button: ButtonMaker, a: LayoutActions): HTMLElement {
  const run = (c: Command) => () => a.command(c);
  el.speed = h(
    "select",
    {
      class: "select", title: "Playback speed ([ and ])", "data-testid": "speed",
      onchange: (e: Event) => {
        const select = e.target as HTMLSelectElement;
        select.blur();
        a.speed(Number(select.value));
      },
    },
    ...SPEEDS.map((s) => h("option", { value: s, selected: s === 1 }, `${s}×`)),
  );
  const group = (...children: HTMLElement[]) => h("div", { class: "group" }, ...children);
  return h(
    "div",
    { class: "transport" },
    group(
      button("prev-cut", icon("prevCut"), "Previous cut (Shift+←)", run({ kind: "jump", direction: -1 })),
      button("step-back", icon("stepBack"), "Previous frame (←)", run({ kind: "step", frames: -1 })),
      button("play", icon("play"), "Play / pause (Space)", run({ kind: "play" }), "btn-play"),
      button("step-forward", icon("stepForward"), "Next frame (→)", run({ kind: "step", frames: 1 })),
      button("next-cut", icon("nextCut"), "Next cut (Shift+→)", run({ kind: "jump", direction: 1 })),
      el.speed,
      button("loop", "Loop", "Loop the segment under the playhead (L); Shift+drag the ruler for any range", run({ kind: "loop" })),
      button("follow", "Follow", "Camera follows the root", a.follow, "active"),
    ),
    group(
      button("accept", "Accept", "Accept the selected candidate (A)", run({ kind: "accept" })),
      button("delete", "Delete", "Delete the selected cut (D)", run({ kind: "delete" })),
      button("insert", "Insert", "Insert a cut at the playhead (I)", run({ kind: "insert" })),
      button("undo", "Undo", "Undo (Z)", run({ kind: "undo" })),
      button("redo", "Redo", "Redo (Shift+Z)", run({ kind: "redo" })),
    ),
    group(
      button("zoom-out", "−", "Zoom out (-)", () => a.zoom(1.5)),
      button("zoom-fit", "Fit", "Show the whole take", () => a.zoom(Infinity)),
      button("zoom-in", "+", "Zoom in (+)", () => a.zoom(1 / 1.5)),
    ),
  );
}
