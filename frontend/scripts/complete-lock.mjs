// The registry this project installs from serves rollup's native packages only for the
// platforms we build on, so `npm install` leaves the other platforms out of
// package-lock.json and `npm ci` then rejects the lock as incomplete. This adds a lock
// entry (version, os, cpu, libc; never fetched: npm skips a foreign platform) for each
// missing optional platform package. Run through `npm run lock` after changing deps.
import { readFileSync, writeFileSync } from "node:fs";

const path = new URL("../package-lock.json", import.meta.url);
const lock = JSON.parse(readFileSync(path, "utf8"));
const PLATFORM = /^@rollup\/rollup-(android|darwin|freebsd|linux|openbsd|openharmony|win32)-([a-z0-9]+)(?:-(\w+))?$/;
const added = [];
for (const meta of Object.values(lock.packages)) {
  for (const [dep, version] of Object.entries(meta.optionalDependencies ?? {})) {
    const key = `node_modules/${dep}`;
    if (lock.packages[key]) continue;
    const m = PLATFORM.exec(dep);
    if (!m) throw new Error(`package-lock.json: optional dependency ${dep} is missing and its platform is unknown`);
    const [, os, cpu, abi] = m;
    const libc = abi?.startsWith("gnu") ? ["glibc"] : abi?.startsWith("musl") ? ["musl"] : undefined;
    lock.packages[key] = { version, cpu: [cpu], dev: true, license: "MIT", ...(libc ? { libc } : {}), optional: true, os: [os] };
    added.push(dep);
  }
}
const entries = Object.entries(lock.packages).sort(([a], [b]) => (a === "" ? -1 : b === "" ? 1 : a < b ? -1 : a > b ? 1 : 0));
lock.packages = Object.fromEntries(entries);
writeFileSync(path, JSON.stringify(lock, null, 2) + "\n");
console.log(`package-lock.json: added ${added.length} platform entries`);
