// Timecode as a studio writes it, HH:MM:SS:FF at the take's own rate, and the "go to"
// prompt's reading of what a person types: a frame number or such a timecode.

/**
 * The whole frames of one timecode second: the take's rate rounded (a 29.97 fps take
 * counts 30 frames a second, non-drop-frame, as most mocap software writes it).
 */
export function timecodeRate(fps: number): number {
  return Math.max(1, Math.round(fps));
}

/** "HH:MM:SS:FF" for a 0-based frame, e.g. frame 1234 at 120 fps → "00:00:10:034". */
export function formatTimecode(frame: number, fps: number): string {
  const rate = timecodeRate(fps);
  const width = Math.max(2, String(rate - 1).length);
  const seconds = Math.floor(frame / rate);
  const parts = [Math.floor(seconds / 3600), Math.floor(seconds / 60) % 60, seconds % 60];
  return [...parts.map((p) => String(p).padStart(2, "0")), String(frame % rate).padStart(width, "0")].join(":");
}

export class GotoError extends Error {}

/**
 * The frame that `text` names: a frame number ("1234") or a timecode ("00:00:10:34",
 * "10:34" = seconds and frames, "01:10:34" = minutes too). Throws GotoError with the
 * reason when the text is neither, or names a frame outside the take.
 */
export function parseGoto(text: string, fps: number, nFrames: number): number {
  const t = text.trim();
  const frame = /^\d+$/.test(t) ? Number(t) : /^\d+(:\d+){1,3}$/.test(t) ? timecodeFrame(t, fps) : null;
  if (frame === null) throw new GotoError(`"${t}" is neither a frame number nor a timecode (HH:MM:SS:FF).`);
  if (frame > nFrames - 1) throw new GotoError(`${t} is past the take's last frame (${nFrames - 1}, ${formatTimecode(nFrames - 1, fps)}).`);
  return frame;
}

function timecodeFrame(text: string, fps: number): number {
  const rate = timecodeRate(fps);
  const [ff, ss = 0, mm = 0, hh = 0] = text.split(":").map(Number).reverse();
  if (ff >= rate) throw new GotoError(`${text}: frames must be below ${rate} at ${fps} fps, not ${ff}.`);
  if (ss >= 60 || mm >= 60) throw new GotoError(`${text}: seconds and minutes must be below 60.`);
  return ((hh * 60 + mm) * 60 + ss) * rate + ff;
}
