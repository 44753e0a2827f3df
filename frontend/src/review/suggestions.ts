// Suggested labels of the own review's unlabelled segments: a frame model's proposal (with
// its probability) or, without one, the label the library suggests. A worker computes them
// after the page opens, so they are asked for until none is pending, less often the longer
// it takes (a busy or stopped worker). Nothing here writes: a suggestion becomes the
// segment's label only when the annotator accepts it (S, commands.ts).

import { get } from "../api/client";
import type { Segment, Suggestions as SuggestionsBody } from "../api/types";

export class Suggestions {
  /** Suggested label and a proposal's probability by "start-stop". */
  private readonly byspan = new Map<string, { label: string | null; probability: number | null }>();
  private decorated: { from: readonly Segment[]; version: number; out: Segment[] } | null = null;
  private version = 0;
  private timer = 0;
  private delay = 2000;
  private stopped = false;

  constructor(private readonly captureId: number, private readonly arrived: () => void) {}

  /** `segment` with the suggested label of the own review's segment of the same span. */
  on(segment: Segment | undefined): Segment | undefined {
    if (!segment || segment.label) return segment;
    const found = this.byspan.get(key(segment));
    return { ...segment, suggested_label: found?.label ?? null, proposed_probability: found?.label ? found.probability : null };
  }

  /** `segments` with their suggestions; the same array until the segments or the
   * suggestions change (the timeline redraws when its segments are another array). */
  all(segments: readonly Segment[]): Segment[] {
    const d = this.decorated;
    if (d && d.from === segments && d.version === this.version) return d.out;
    const out = segments.map((s) => this.on(s) as Segment);
    this.decorated = { from: segments, version: this.version, out };
    return out;
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
    for (const s of body.suggestions) this.byspan.set(`${s.start}-${s.stop}`, { label: s.label, probability: s.probability });
    this.version++;
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
