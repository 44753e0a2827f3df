// Shapes and calls of assignments, queues and returns (docs/api.md, "Assignments and queues").

import { get, post } from "../api/client";
import type { Assignment, Member, QueueItem, QueueState } from "../api/types";

export type { Assignment, Member, QueueItem, QueueState };

export const STATE_TEXT: Record<QueueState, string> = {
  assigned: "assigned",
  in_progress: "in progress",
  returned: "returned",
  submitted: "submitted",
};

/** States that still ask something of the annotator, in the order work is picked up. */
export const OPEN_STATES: QueueState[] = ["returned", "in_progress", "assigned"];

export function queueUrl(project?: number | null, user?: string | null): string {
  const q = new URLSearchParams();
  if (project) q.set("project", String(project));
  if (user) q.set("user", user);
  const text = q.toString();
  return `/api/queue/${text ? `?${text}` : ""}`;
}

export const loadQueue = (project?: number | null, user?: string | null) => get<QueueItem[]>(queueUrl(project, user));

/** The oldest open item of the caller's queue other than `exclude`, if any. */
export async function nextInQueue(project: number | null, exclude: number): Promise<QueueItem | null> {
  const items = await loadQueue(project);
  return items.find((i) => i.capture.id !== exclude && OPEN_STATES.includes(i.state)) ?? null;
}

export const assign = (project: number, captures: number[], annotators: string[], perCapture: number | null) =>
  post<Assignment[]>(`/api/projects/${project}/assignments/`, { captures, annotators, per_capture: perCapture });

export const returnReview = (capture: number, review: number, comment: string) =>
  post(`/api/captures/${capture}/reviews/${review}/return/`, { comment });
