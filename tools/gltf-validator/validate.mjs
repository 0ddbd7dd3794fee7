// Validates glTF files with the Khronos glTF validator and prints its findings.
// Usage: node tools/gltf-validator/validate.mjs <file.glb>...
// Exits 1 if any file has an error (warnings and infos are printed, not counted as failures).
import { readFile } from "node:fs/promises";
import { basename } from "node:path";
import validator from "gltf-validator";

const severities = ["error", "warning", "info", "hint"];
const files = process.argv.slice(2);
if (files.length === 0) {
  console.error("usage: node tools/gltf-validator/validate.mjs <file.glb>...");
  process.exit(2);
}
let failed = false;
for (const file of files) {
  let bytes;
  try {
    bytes = new Uint8Array(await readFile(file));
  } catch (e) {
    console.error(`error: cannot read ${file}: ${e.message}`);
    process.exit(2);
  }
  const report = await validator.validateBytes(bytes, {
    uri: basename(file),
    maxIssues: 0,
  });
  const i = report.issues;
  console.log(
    `${file}: ${i.numErrors} errors, ${i.numWarnings} warnings, ${i.numInfos} infos, ` +
      `${i.numHints} hints (glTF validator ${report.validatorVersion})`,
  );
  for (const m of i.messages) {
    console.log(`  ${severities[m.severity]} ${m.code} ${m.pointer ?? ""}: ${m.message}`);
  }
  failed ||= i.numErrors > 0;
}
process.exit(failed ? 1 : 0);
