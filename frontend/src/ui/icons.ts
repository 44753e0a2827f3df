// Transport icons as inline SVG: font glyphs like ⏮ are missing from many system fonts.

const PATHS: Record<string, string> = {
  play: "M5 3l11 7-11 7z",
  pause: "M5 3h4v14H5zM11 3h4v14h-4z",
  stepBack: "M14 4v12l-8-6zM4 4h2v12H4z",
  stepForward: "M6 4v12l8-6zM14 4h2v12h-2z",
  prevCut: "M10 4v12L3 10zM17 4v12l-7-6zM1 4h2v12H1z",
  nextCut: "M10 4v12l7-6zM3 4v12l7-6zM17 4h2v12h-2z",
  loop: "M4 9a6 6 0 0 1 10-4l1-2 1 6-6-1 2-1.5A4 4 0 0 0 6 9zM16 11a6 6 0 0 1-10 4l-1 2-1-6 6 1-2 1.5A4 4 0 0 0 14 11z",
};

export function icon(name: keyof typeof PATHS): SVGSVGElement {
  const ns = "http://www.w3.org/2000/svg";
  const svg = document.createElementNS(ns, "svg");
  svg.setAttribute("viewBox", "0 0 20 20");
  svg.setAttribute("width", "14");
  svg.setAttribute("height", "14");
  svg.setAttribute("aria-hidden", "true");
  const path = document.createElementNS(ns, "path");
  path.setAttribute("d", PATHS[name]);
  path.setAttribute("fill", "currentColor");
  svg.append(path);
  return svg;
}
