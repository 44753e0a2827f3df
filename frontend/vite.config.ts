import { defineConfig } from "vitest/config";

// Django serves the built files under /static/ (WhiteNoise) and index.html itself,
// so every asset URL must start with /static/.
export default defineConfig({
  base: "/static/",
  build: {
    outDir: "dist",
    emptyOutDir: true,
    chunkSizeWarningLimit: 900,
  },
  test: {
    include: ["tests/**/*.test.ts"],
    environment: "node",
  },
});
