// Validates GLB files with the Khronos glTF validator: `node validate-glb.mjs FILE...` prints one JSON
// line per file, {file, errors, warnings, infos, messages} (messages: the errors and warnings, at most 20).
import { readFile } from "node:fs/promises";
import validator from "gltf-validator";

for (const file of process.argv.slice(2)) {
  const report = await validator.validateBytes(new Uint8Array(await readFile(file)), { maxIssues: 1000 });
  const issues = report.issues;
  const messages = issues.messages.filter((m) => m.severity <= 1).slice(0, 20)
    .map((m) => `${m.code} ${m.pointer ?? ""}: ${m.message}`);
  console.log(JSON.stringify({ file, errors: issues.numErrors, warnings: issues.numWarnings,
                               infos: issues.numInfos, messages }));
}
