// Suggested labels of the own review's unlabelled segments. A worker computes them after
// the page opens, so they are asked for until none is pending, less often the longer it
// takes (a busy or stopped worker).

import { get } from "../api/client";
import type { Segment, Suggestions as SuggestionsBody } from "../api/types";

export class Suggestions {
  /** Suggested label by "start-stop". */
  private readonly byspan = new Map<string, string | null>();
  private timer = 0;
  private delay = 2000;
  private stopped = false;

  constructor(private readonly captureId: number, private readonly arrived: () => void) {}

  /** `segment` with the suggested label of the own review's segment of the same span. */
  on(segment: Segment | undefined): Segment | undefined {
    if (!segment || segment.label) return segment;
    return { ...segment, suggested_label: this.byspan.get(key(segment)) ?? null };
  }

  /** An edit made new segments: ask for theirs once the edits settle. */
  askForNew(segments: readonly Segment[]): void {
    if (segments.some((s) => !s.label && !this.byspan.has(key(s)))) this.ask(800);
  }

  ask(delayMs: number): void {
    clearTimeout(this.timer);
    this.timer = window.setTimeout(() => void this.load(), delayMs);
  }

  async load(): Promise<void> {
    const body = await get<SuggestionsBody>(`/api/captures/${this.captureId}/review/suggestions/`).catch(() => null);
    if (!body || this.stopped) return;
    for (const s of body.suggestions) this.byspan.set(`${s.start}-${s.stop}`, s.label);
    this.arrived();
    if (!body.pending) {
      this.delay = 2000;
      return;
    }
    this.ask(this.delay);
    this.delay = Math.min(this.delay * 1.5, 15000);
  }

  dispose(): void {
    this.stopped = true;
    clearTimeout(this.timer);
  }
}

const key = (s: Pick<Segment, "start" | "stop">) => `${s.start}-${s.stop}`;
