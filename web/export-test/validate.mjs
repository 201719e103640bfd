// The Khronos glTF Validator over exported files: prints each file's counts and every message,
// and exits non-zero on any error or warning (infos and hints are printed, not counted).
//
//   node validate.mjs FILE.glb [FILE.gltf ...]
import fs from 'node:fs';
import path from 'node:path';
import validator from 'gltf-validator';

/** The validator's report on `file` (a .glb, or a .gltf with its resources beside it). */
export async function validate(file) {
  const bytes = new Uint8Array(fs.readFileSync(file));
  return validator.validateBytes(bytes, {
    uri: path.basename(file),
    maxIssues: 0,
    externalResourceFunction: (uri) =>
      new Promise((resolve, reject) => {
        fs.readFile(path.resolve(path.dirname(file), decodeURIComponent(uri)), (error, data) =>
          error ? reject(error.toString()) : resolve(new Uint8Array(data)));
      }),
  });
}

/** One line per file and one per message. */
export function summary(file, report) {
  const { numErrors, numWarnings, numInfos, numHints, messages } = report.issues;
  const info = report.info || {};
  const lines = [`${file}: ${numErrors} errors, ${numWarnings} warnings, ${numInfos} infos, ${numHints} hints; ` +
    `${info.drawCallCount} draw calls, ${info.totalVertexCount} vertices, ${info.totalTriangleCount} triangles, ` +
    `${info.materialCount} materials, ${info.animationCount} animations, skins: ${info.hasSkins}`];
  for (const m of messages) lines.push(`  [${['error', 'warning', 'info', 'hint'][m.severity]}] ${m.code} ${m.pointer || ''}: ${m.message}`);
  return lines.join('\n');
}

if (process.argv[1] && path.resolve(process.argv[1]) === path.resolve(new URL(import.meta.url).pathname)) {
  let failed = false;
  for (const file of process.argv.slice(2)) {
    const report = await validate(file);
    console.log(summary(file, report));
    failed ||= report.issues.numErrors > 0 || report.issues.numWarnings > 0;
  }
  process.exit(failed ? 1 : 0);
}
