// The Khronos glTF validator (npm `gltf-validator`, a frontend dev dependency) on one file:
//   node gltf_validate.cjs FRONTEND_DIR CLIP.glb
// prints the validator's report as JSON (issues.numErrors, issues.messages, info...).
const fs = require("node:fs");
const path = require("node:path");

const [frontend, file] = process.argv.slice(2);
const validator = require(path.join(frontend, "node_modules", "gltf-validator"));
validator
  .validateBytes(new Uint8Array(fs.readFileSync(file)), { maxIssues: 50 })
  .then((report) => process.stdout.write(JSON.stringify(report) + "\n"))
  .catch((error) => {
    process.stderr.write(String(error) + "\n");
    process.exit(2);
  });
