import type { Cut, Review } from "../src/api/types";

export function cut(id: number, frame: number, fate: Cut["fate"] = "pending", confidence = 0.5): Cut {
  return { id, origin: "candidate", fate, candidate_frame: frame, frame, confidence };
}

/** A review of a 1,000-frame take with candidates at 200, 500 and 800. */
export function review(cuts: Cut[] = [cut(1, 200), cut(2, 500), cut(3, 800)]): Review {
  return {
    id: 7, capture: 3, annotator: { id: 1, username: "ann" }, run: 1, status: "in_progress", version: 4,
    return_comment: "",
    cuts,
    segments: [
      { index: 0, start: 0, stop: 200, label: "walk" },
      { index: 1, start: 200, stop: 500, label: null },
      { index: 2, start: 500, stop: 800, label: "punch" },
      { index: 3, start: 800, stop: 1000, label: null },
    ],
  };
}
