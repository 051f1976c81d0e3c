// Validates each .gltf given (files or folders) with the Khronos glTF-Validator (npm), as
// benches/anchors.sh runs it: every report in full (maxIssues 0), resources read from disk.
const validator = require('gltf-validator');
const fs = require('fs');
const path = require('path');
function collect(p, out) {
  if (fs.statSync(p).isDirectory()) for (const e of fs.readdirSync(p)) collect(path.join(p, e), out);
  else if (/\.(gltf|glb)$/i.test(p)) out.push(p);
}
(async () => {
  const files = [];
  for (const a of process.argv.slice(2)) collect(a, files);
  let errors = 0;
  for (const f of files) {
    const data = new Uint8Array(fs.readFileSync(f));
    const report = await validator.validateBytes(data, {
      uri: f, maxIssues: 0,
      externalResourceFunction: (uri) => new Promise((res, rej) => {
        fs.readFile(path.join(path.dirname(f), decodeURIComponent(uri)), (e, d) => e ? rej(e.toString()) : res(new Uint8Array(d)));
      }),
    });
    errors += report.issues.numErrors;
  }
  console.log(`${files.length} files, ${errors} errors`);
})();
