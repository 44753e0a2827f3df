// Shapes of the HTTP API (docs/api.md). Frame numbers are the capture's own, 0-based.

export interface Label {
  id: number;
  name: string;
  color: string;
  hotkey: string | null;
  position?: number;
  /** Retired: stays on existing segments, not offered for new ones. */
  retired?: boolean;
}

export type Role = "annotator" | "reviewer" | "admin";

export interface Project {
  id: number;
  name: string;
  role: Role;
  default_method: string;
  default_params: Record<string, unknown>;
  labels: Label[];
  annotators_pick_unassigned?: boolean;
}

export interface Me {
  id: number;
  username: string;
  projects: { id: number; name: string; role: Role }[];
  /** What the service admits (CUTROOM_MAX_JOINTS…). */
  limits?: { max_joints: number };
  can_create_accounts?: boolean;
}

export interface Skeleton {
  joints: string[];
  parents: number[];
  height: number;
  up: string;
}

export type CaptureStatus = "queued" | "processing" | "ready" | "failed";

export interface Run {
  id: number;
  method: string;
  params: Record<string, unknown>;
  status: string;
  error: string | null;
  created_at: string;
  finished_at: string | null;
  candidates: { frame: number; confidence: number }[];
  /** The project model the candidates came from; null: the zero-shot detector. */
  model_version?: number | null;
  model_n_takes?: number | null;
}

export interface Capture {
  id: number;
  project: number;
  name: string;
  format: "bvh" | "amc" | "fbx";
  status: CaptureStatus;
  error: string | null;
  fps: number;
  n_frames: number;
  duration: number;
  n_joints: number;
  checksum: string;
  rest_pose_frame: number | null;
  created_at: string;
  latest_run: Run | null;
  skeleton: Skeleton | null;
  /** FBX: which animation of the file ("" otherwise); another animation's capture id. */
  animation?: string;
  source?: number | null;
  duplicate?: boolean;
}

/** A row of the capture list: no skeleton, the latest run summarised. */
export interface RunSummary {
  id: number;
  method: string;
  status: string;
  error: string | null;
  created_at: string;
  finished_at: string | null;
  n_candidates: number;
  model_version?: number | null;
  model_n_takes?: number | null;
}

export interface CaptureSummary extends Omit<Capture, "skeleton" | "latest_run"> {
  latest_run: RunSummary | null;
  /** Someone opened it for review; its candidates can no longer be re-detected. */
  review_started?: boolean;
  /** Who is assigned, and each review's annotator and state. */
  team?: { assigned: string[]; reviews: { id: number; annotator: string; status: Review["status"] }[] };
}

export interface Page<T> {
  count: number;
  next: string | null;
  previous: string | null;
  results: T[];
}

export interface Signal {
  name: string;
  start: number;
  step: number;
  values: number[];
}

export interface SignalResponse {
  run: number;
  fps: number;
  n_frames: number;
  signals: Signal[];
}

export interface FramesResponse {
  start: number;
  stop: number;
  step: number;
  n_frames: number;
  n_joints: number;
  dtype: "float32";
  data: string;
}

export type Fate = "pending" | "accepted" | "moved" | "deleted";

export interface Cut {
  id: number;
  origin: "candidate" | "inserted";
  fate: Fate;
  candidate_frame: number | null;
  frame: number;
  confidence: number | null;
}

export interface Segment {
  index: number;
  start: number;
  stop: number;
  label: string | null;
  /** Label of the most alike library segments, for an unlabelled segment: not sent with
   * the review; the page fills it in from `Suggestions`. */
  suggested_label?: string | null;
}

/** `GET /api/captures/{id}/review/suggestions/`: computed by a worker, `pending` until all are. */
export interface Suggestions {
  pending: boolean;
  suggestions: { start: number; stop: number; label: string | null }[];
}

export interface Review {
  /** null: the caller has not started a review; this is the one the first write starts. */
  id: number | null;
  capture: number;
  annotator: { id: number; username: string };
  run: number | null;
  status: "in_progress" | "submitted" | "returned" | "not_started";
  version: number;
  return_comment?: string;
  cuts: Cut[];
  segments: Segment[];
  adaptation?: Adaptation;
}

/** Where a review's candidates came from, and the project's learnt model. */
export interface Adaptation {
  /** Model version of the review's run; null: the zero-shot detector. */
  model_version: number | null;
  /** Reviewed takes that model learnt from. */
  n_takes: number | null;
  project_model: { version: number; n_takes: number; n_cuts: number } | null;
  /** A training is queued or running. */
  training: boolean;
  /** Why the last training failed (the project keeps its previous model). */
  training_error: string | null;
}

export interface ReviewEvent {
  id: number;
  user: string | { id: number; username: string };
  action: string;
  cut: number | null;
  before: unknown;
  after: unknown;
  created_at: string;
}
