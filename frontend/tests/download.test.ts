import { describe, expect, it } from "vitest";
import { attachmentName, clipsWhat, formatBytes } from "../src/library/download";

describe("export downloads", () => {
  it("says how much has arrived in the unit a person reads", () => {
    expect(formatBytes(512)).toBe("512 B");
    expect(formatBytes(1536)).toBe("1.5 kB");
    expect(formatBytes(5 * 1024 * 1024)).toBe("5.0 MB");
  });

  it("saves under the server's file name, else the fallback", () => {
    expect(attachmentName('attachment; filename="segments-glb.zip"', "x.zip")).toBe("segments-glb.zip");
    expect(attachmentName(null, "segment-3.fbx")).toBe("segment-3.fbx");
  });
});

describe("bulk export progress", () => {
  it("test_it_counts_the_clips_the_server_writes_not_every_matching_segment", () => {
    expect(clipsWhat("2", "BVH")).toBe("2 clips as BVH");
    expect(clipsWhat("1", "C3D (points)")).toBe("1 clip as C3D (points)");
    expect(clipsWhat(null, "BVH")).toBeNull();
    expect(clipsWhat("two", "BVH")).toBeNull();
  });
});
