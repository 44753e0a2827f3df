// Shapes of the HTTP API, named for the code that uses them. Frame numbers are the
// capture's own, 0-based. They are aliases of schema.d.ts, which `npm run api-types`
// generates from the server's OpenAPI schema (the serializers are the source of truth:
// change them, not these, and regenerate; tests/segmentation/test_api_schema.py fails
// when schema.d.ts is stale).
import type { components } from "./schema";

type Schemas = components["schemas"];

export type Label = Schemas["Label"];
/** What picking a label needs (the adjudication page's labels carry no more). */
export type LabelChoice = Schemas["AdjudicationLabel"];
export type Role = Schemas["RoleEnum"];
export type Project = Schemas["Project"];
export type Me = Schemas["Me"];
export type Skeleton = Schemas["Skeleton"];
export type CaptureStatus = Schemas["JobStatusEnum"];
export type Run = Schemas["Run"];
export type Capture = Schemas["Capture"];
/** A capture whose ingest finished: its frame rate, length and skeleton are known. */
export type ReadyCapture = Capture & { status: "ready"; fps: number; n_frames: number; skeleton: Skeleton };
/** `POST /api/captures/`: the capture, and whether the project already had the file. */
export type Uploaded = Schemas["Uploaded"];
/** A row of the capture list: no skeleton, the latest run summarised. */
export type RunSummary = Schemas["RunSummary"];
export type CaptureSummary = Schemas["CaptureList"];

/** A page of a paginated list (`count`, `next`, `previous`, `results`). */
export interface Page<T> {
  count: number;
  next: string | null;
  previous: string | null;
  results: T[];
}

export type Signal = Schemas["Signal"];
export type SignalResponse = Schemas["Signals"];
export type FramesResponse = Schemas["Frames"];
export type Fate = Schemas["CutFateEnum"];
/** A cut as the server sends it: no id yet (null) in a review not started. */
export type ApiCut = Schemas["Cut"];
/** A cut as the pages edit it: the server's id, or a temporary negative one given to an
 * unstarted review's candidates (review/state.ts withTempIds). */
export type Cut = ApiCut & { id: number };

/** A review's segment; `suggested_label` is not sent with the review: the page fills it in
 * from `Suggestions` for an unlabelled segment, with `proposed_probability` when it is a
 * frame model's proposal (null: a label the library suggests). */
export type Segment = Omit<Schemas["ReviewSegment"], "attributes"> & { attributes?: Schemas["ReviewSegment"]["attributes"]; suggested_label?: string | null; proposed_probability?: number | null };
/** A segment's attribute values by attribute name: an option, a note or true/false. Absent
 * on a segment the page derived itself until the server answers. */
export type AttributeValues = NonNullable<Segment["attributes"]>;
/** One attribute of a project's segment schema. */
export type SegmentAttribute = Schemas["Attribute"];
/** A comment on a review, or a reply (`parent`). */
export type ReviewComment = Schemas["Comment"];

/** `GET /api/captures/{id}/review/suggestions/`: computed by a worker, `pending` until all are. */
export type Suggestions = Schemas["Suggestions"];
/** A review as the server sends it; `id` null: the caller has not started one, and this is
 * the one the first write starts. */
export type ApiReview = Schemas["Review"];
/** `GET /api/captures/{id}/review/`: the review the page opens, and where its candidates
 * came from (edits answer with the review alone). */
export type OpenedReview = Schemas["ReviewPage"];
/** A review as the pages hold it: every cut has an id (see `Cut`). */
export type Review = Omit<ApiReview, "cuts" | "segments"> & { cuts: Cut[]; segments: Segment[] };
/** Where a review's candidates came from, and the project's learnt model. */
export type Adaptation = Schemas["Adaptation"];
/** A model's own figure: each reviewed take scored by a model fitted without it. */
export type HeldOut = Schemas["HeldOut"];
export type ReviewEvent = Schemas["Event"];

export function isReady(capture: Capture): capture is ReadyCapture {
  return capture.status === "ready" && capture.fps !== null && capture.n_frames !== null && capture.skeleton !== null;
}

// Assignments, queues, members and invitations.
export type QueueState = Schemas["QueueStateEnum"];
export type QueueItem = Schemas["QueueItem"];
export type Assignment = Schemas["Assignment"];
export type Member = Schemas["Member"];
/** A pending invitation as the project's admins see it. */
export type Invitation = Schemas["Invitation"];
/** An invitation as the invitee sees it: which project, what role, from whom. */
export type MyInvitation = Schemas["MyInvitation"];
