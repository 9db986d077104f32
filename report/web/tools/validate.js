// Runs the Khronos glTF-Validator (npm gltf-validator, pinned in package-lock.json) on .glb files.
// Usage: node validate.js FILE.glb...   Prints one line per file (errors, warnings, infos and the
// first messages); exits 1 when any file has an error or a warning, 2 on a usage error.
'use strict';
const fs = require('fs');
const path = require('path');
const validator = require('gltf-validator');

async function main(files) {
  if (files.length === 0) {
    console.error('usage: node validate.js FILE.glb...');
    return 2;
  }
  let failed = false;
  for (const file of files) {
    const report = await validator.validateBytes(new Uint8Array(fs.readFileSync(file)), {
      uri: path.basename(file),
      maxIssues: 100,
      externalResourceFunction: () => Promise.reject(new Error('no external resources')),
    });
    const issues = report.issues;
    const bad = issues.numErrors > 0 || issues.numWarnings > 0;
    failed = failed || bad;
    console.log(`${file}: ${issues.numErrors} errors, ${issues.numWarnings} warnings, ` +
                `${issues.numInfos} infos, ${issues.numHints} hints`);
    for (const message of issues.messages.filter((m) => m.severity <= 2).slice(0, 20)) {
      console.log(`  ${message.code} ${message.pointer || ''}: ${message.message}`);
    }
  }
  return failed ? 1 : 0;
}

main(process.argv.slice(2)).then((code) => process.exit(code), (error) => {
  console.error(error.stack || String(error));
  process.exit(2);
});
