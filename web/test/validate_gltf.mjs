// Runs the Khronos glTF validator (npm gltf-validator) on each GLB given and prints one JSON line per
// file: {"file", "errors", "warnings", "infos", "messages": [first 20 errors/warnings]}.
// Exit status 0 only when no file has an error. Used by the native export tests (tests/native/export.rs).
import { readFile } from "node:fs/promises";
import validator from "gltf-validator";

let failed = false;
for (const file of process.argv.slice(2)) {
  const bytes = new Uint8Array(await readFile(file));
  const report = await validator.validateBytes(bytes, {
    maxIssues: 1000,
    // A GLB carries everything; an external resource would be a bug.
    externalResourceFunction: (uri) => Promise.reject(new Error(`external resource ${uri}`)),
  });
  const issues = report.issues;
  const messages = issues.messages
    .filter((m) => m.severity <= 1)
    .slice(0, 20)
    .map((m) => `${m.severity === 0 ? "error" : "warning"} ${m.code} at ${m.pointer ?? "-"}: ${m.message}`);
  console.log(JSON.stringify({
    file,
    errors: issues.numErrors,
    warnings: issues.numWarnings,
    infos: issues.numInfos,
    messages,
  }));
  if (issues.numErrors > 0) failed = true;
}
process.exit(failed ? 1 : 0);
