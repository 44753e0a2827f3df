// Shapes of the library, agreement, adjudication and dashboard API (docs/api.md).

export interface LibrarySegment {
  id: number;
  project: number;
  capture: { id: number; name: string };
  review: number | null;
  annotator: { id: number; username: string } | null;
  gold: boolean;
  superseded: boolean;
  label: string;
  color: string;
  start: number;
  stop: number;
  fps: number;
  duration: number;
  agreement: number | null;
  distance?: number;
}

export interface Span {
  start: number;
  stop: number;
  label: string | null;
}

export interface Pair {
  a: { review: number; annotator: string };
  b: { review: number; annotator: string };
  precision: number | null;
  recall: number | null;
  f1: number | null;
  matched: number;
  kappa: number | null;
}

export interface Agreement {
  capture: number;
  tolerance_s: number;
  n_reviews: number;
  pairs: Pair[];
  boundary_f1: number | null;
  labels: { method: "cohen_kappa" | "krippendorff_alpha" | null; value: number | null };
  alpha: number | null;
  per_label: { label: string; overlap: number | null; frames: number }[];
}

export interface Gold {
  version: number;
  cuts: number[];
  labels: (string | null)[];
  segments: Span[];
  adjudicator: string | null;
  source_review: number | null;
  updated_at: string;
}

export interface Adjudication {
  capture: { id: number; name: string; fps: number; n_frames: number; project: number };
  labels: { name: string; color: string; hotkey: string | null }[];
  reviews: { id: number; annotator: { id: number; username: string }; status: string; cuts: number[]; segments: Span[] }[];
  gold: Gold | null;
  agreement: Agreement;
}

export type CaptureState = "unreviewed" | "in_review" | "agreed" | "adjudicated";

export interface Dashboard {
  project: number;
  states: Record<CaptureState, number>;
  captures: { id: number; name: string; state: CaptureState; reviews: number; submitted: number; boundary_f1: number | null; label_agreement: number | null;
    assigned?: string[]; review_states?: { id: number; annotator: string; status: "in_progress" | "submitted" | "returned" }[] }[];
  annotators: {
    id: number;
    username: string;
    submitted: number;
    in_progress: number;
    edits: Record<string, number>;
    edits_total: number;
    edits_per_review: number | null;
    median_minutes_per_review: number | null;
  }[];
  labels: { label: string; overlap: number | null; frames: number; captures: number }[];
  library: { total: number; gold: number };
}
