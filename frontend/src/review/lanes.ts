// What a signal lane draws, independent of the canvas: the value range it is scaled to
// (robust to a stray spike such as a T-pose frame) and its samples reduced to one min-max
// pair per pixel column through a min-max pyramid, so a view of an hour-long take costs a
// few thousand operations instead of a pass over every frame.

/** The values a lane spans and whether samples lie beyond them (drawn clipped, and marked). */
export interface LaneRange {
  lo: number;
  hi: number;
  clippedLow: boolean;
  clippedHigh: boolean;
}

/** Share of the samples at each end that may fall outside the bulk of the range. */
const TAIL = 0.005;
/** Outliers are clipped only when they reach further than this share of the bulk's span beyond it. */
const REACH = 0.5;
/** Room left above and below a clipped bulk, as a share of its span. */
const HEADROOM = 0.05;
/** Percentiles are taken on at most this many evenly spaced samples. */
const SAMPLE = 20_000;

/**
 * The range a lane is scaled to: the finite min and max, unless a few samples reach far
 * beyond the rest. Then the range is the 0.5th to 99.5th percentile (with a little
 * headroom) and the far samples are clipped: one T-pose frame of speed 193,053 against a
 * median of 3,760 no longer flattens the lane. A flat signal is widened to a unit range.
 */
export function robustRange(values: ArrayLike<number>): LaneRange {
  const [min, max] = extremes(values);
  if (min === Infinity) return { lo: 0, hi: 1, clippedLow: false, clippedHigh: false };
  if (max === min) return { lo: min - 0.5, hi: max + 0.5, clippedLow: false, clippedHigh: false };
  const sorted = finiteSample(values, SAMPLE).sort();
  const bulkLo = quantile(sorted, TAIL);
  const bulkHi = quantile(sorted, 1 - TAIL);
  const span = bulkHi - bulkLo;
  if (span <= 0) return { lo: min, hi: max, clippedLow: false, clippedHigh: false };
  const clippedLow = min < bulkLo - REACH * span;
  const clippedHigh = max > bulkHi + REACH * span;
  return {
    lo: clippedLow ? bulkLo - HEADROOM * span : min,
    hi: clippedHigh ? bulkHi + HEADROOM * span : max,
    clippedLow,
    clippedHigh,
  };
}

function extremes(values: ArrayLike<number>): [number, number] {
  let lo = Infinity;
  let hi = -Infinity;
  for (let i = 0; i < values.length; i++) {
    const v = values[i];
    if (!Number.isFinite(v)) continue;
    if (v < lo) lo = v;
    if (v > hi) hi = v;
  }
  return [lo, hi];
}

function finiteSample(values: ArrayLike<number>, limit: number): Float64Array {
  const stride = Math.max(1, Math.floor(values.length / limit));
  const out: number[] = [];
  for (let i = 0; i < values.length; i += stride) if (Number.isFinite(values[i])) out.push(values[i]);
  return Float64Array.from(out);
}

/** Linear-interpolated quantile `q` (0..1) of ascending `sorted`. */
export function quantile(sorted: ArrayLike<number>, q: number): number {
  const at = q * (sorted.length - 1);
  const i = Math.floor(at);
  const j = Math.min(i + 1, sorted.length - 1);
  return sorted[i] + (sorted[j] - sorted[i]) * (at - i);
}

/**
 * Min and max of a signal over blocks of 1, 2, 4 … samples. Level k holds, for each block
 * of 2^k samples, the least and greatest finite value (+Infinity / -Infinity when the
 * block has none). Built once per signal in O(n); queried per view in O(width).
 */
export class MinMaxPyramid {
  readonly levels: { min: Float32Array; max: Float32Array }[] = [];

  constructor(values: ArrayLike<number>) {
    const min = new Float32Array(values.length);
    const max = new Float32Array(values.length);
    for (let i = 0; i < values.length; i++) {
      const v = values[i];
      const finite = Number.isFinite(v);
      min[i] = finite ? v : Infinity;
      max[i] = finite ? v : -Infinity;
    }
    this.levels.push({ min, max });
    while (this.levels[this.levels.length - 1].min.length > 1) this.levels.push(halve(this.levels[this.levels.length - 1]));
  }

  get length(): number {
    return this.levels[0].min.length;
  }

  /**
   * Per pixel column c of `width`, the min and max of the samples starting in
   * [first + c·perPx, first + (c+1)·perPx) (fractional sample indices), NaN where none.
   * Samples are taken in blocks of the largest power of two not above `perPx`, each block
   * counted in the column where it starts: no sample is lost or counted twice, and a
   * column's edges are exact to within one block (less than a pixel).
   */
  columns(first: number, perPx: number, width: number): { min: Float32Array; max: Float32Array } {
    const cols = Math.max(Math.ceil(width), 0);
    const lo = new Float32Array(cols).fill(NaN);
    const hi = new Float32Array(cols).fill(NaN);
    const k = Math.min(Math.max(Math.floor(Math.log2(Math.max(perPx, 1))), 0), this.levels.length - 1);
    const level = this.levels[k];
    const block = 2 ** k;
    const n = level.min.length;
    const b0 = Math.max(Math.ceil(first / block), 0);
    for (let b = b0; b < n; b++) {
      const c = Math.floor((b * block - first) / perPx);
      if (c >= cols) break;
      if (c < 0 || level.min[b] === Infinity) continue;
      if (!(lo[c] <= level.min[b])) lo[c] = level.min[b];
      if (!(hi[c] >= level.max[b])) hi[c] = level.max[b];
    }
    return { min: lo, max: hi };
  }
}

function halve(level: { min: Float32Array; max: Float32Array }): { min: Float32Array; max: Float32Array } {
  const n = Math.ceil(level.min.length / 2);
  const min = new Float32Array(n);
  const max = new Float32Array(n);
  for (let i = 0; i < n; i++) {
    const j = Math.min(2 * i + 1, level.min.length - 1);
    min[i] = Math.min(level.min[2 * i], level.min[j]);
    max[i] = Math.max(level.max[2 * i], level.max[j]);
  }
  return { min, max };
}
