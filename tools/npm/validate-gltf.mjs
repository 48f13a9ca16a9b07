// Validates glTF / GLB files with the Khronos glTF validator (npm gltf-validator).
// Usage: node tools/npm/validate-gltf.mjs FILE...
// Prints one JSON line per file {file, errors, warnings, infos, messages} and exits 1 when any
// file has errors.
import fs from 'node:fs';
import path from 'node:path';
import validator from 'gltf-validator';

let failed = false;
for (const file of process.argv.slice(2)) {
  const bytes = new Uint8Array(fs.readFileSync(file));
  const report = await validator.validateBytes(bytes, {
    uri: path.basename(file),
    maxIssues: 50,
    externalResourceFunction: (uri) =>
      new Promise((resolve, reject) => {
        fs.readFile(path.join(path.dirname(file), decodeURIComponent(uri)), (err, data) =>
          err ? reject(err.toString()) : resolve(new Uint8Array(data)));
      }),
  });
  const issues = report.issues;
  const out = {
    file,
    errors: issues.numErrors,
    warnings: issues.numWarnings,
    infos: issues.numInfos,
    messages: issues.messages.map((m) => `${m.severity === 0 ? 'error' : m.severity === 1 ? 'warning' : 'info'} ${m.code}: ${m.message} ${m.pointer ?? ''}`),
  };
  console.log(JSON.stringify(out));
  if (issues.numErrors > 0) failed = true;
}
process.exit(failed ? 1 : 0);
