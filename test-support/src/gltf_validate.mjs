// The Khronos glTF-Validator (npm gltf-validator) on one .glb or .gltf file,
// for test_support::gltf::validate. Run as
//   node --input-type=module - FILE   (this script on stdin)
// from the folder whose node_modules holds gltf-validator
// (target/browser-e2e). External buffers and images are read relative to
// FILE. Prints one line a result, tab-separated, nothing else on stdout:
//   validator VERSION
//   issue SEVERITY CODE POINTER MESSAGE   (severity: error, warning, info, hint)
//   counts ERRORS WARNINGS INFOS HINTS TRUNCATED
// Exit codes: 0 the validator ran (whatever it found), 3 gltf-validator is
// not installed, 1 anything else (an unreadable file, a file that is neither
// glTF nor GLB).
import { readFile } from 'node:fs/promises';
import path from 'node:path';

let validator;
try {
  validator = await import('gltf-validator');
} catch (e) {
  if (e && e.code === 'ERR_MODULE_NOT_FOUND') {
    console.error(`gltf-validator is not installed in ${process.cwd()}: ${e.message}`);
    process.exit(3);
  }
  throw e;
}

const file = process.argv[2];
if (!file) {
  console.error('usage: node --input-type=module - FILE < gltf_validate.mjs');
  process.exit(1);
}
const full = path.resolve(file);
const bytes = new Uint8Array(await readFile(full));
const oneLine = (s) => String(s ?? '').replace(/[\t\r\n]+/g, ' ');
let report;
try {
  report = await validator.validateBytes(bytes, {
    uri: path.basename(full),
    maxIssues: 0, // every issue, not the first 100
    writeTimestamp: false,
    externalResourceFunction: async (uri) => {
      const resource = path.resolve(path.dirname(full), decodeURIComponent(uri));
      try {
        return new Uint8Array(await readFile(resource));
      } catch (e) {
        // The validator reports the rejection as an IO_ERROR issue.
        throw `${resource}: ${e.message}`;
      }
    },
  });
} catch (e) {
  // A rejection: the validator could not even tell the format.
  console.error(`the validator refused ${full}: ${e}`);
  process.exit(1);
}
const severities = ['error', 'warning', 'info', 'hint'];
console.log(`validator\t${validator.version()}`);
for (const m of report.issues.messages) {
  const where = m.pointer ?? (m.offset !== undefined ? `byte ${m.offset}` : '');
  console.log(['issue', severities[m.severity] ?? `severity-${m.severity}`, m.code, oneLine(where), oneLine(m.message)].join('\t'));
}
const i = report.issues;
console.log(['counts', i.numErrors, i.numWarnings, i.numInfos, i.numHints, i.truncated ? 'truncated' : 'complete'].join('\t'));
