#!/usr/bin/env node
// Validates glTF files (.glb or .gltf with embedded buffers) with the Khronos
// glTF validator (npm gltf-validator, scripts/install-gltf-validator.sh).
//   usage: node scripts/gltf-validate.js VALIDATOR_PREFIX FILE...
// Prints each file's counts of errors, warnings, infos and hints and every
// error and warning; exits 1 if any file has an error or cannot be read, 2 on
// bad usage or a missing validator.
'use strict';
const fs = require('fs');
const path = require('path');

if (process.argv.length < 4) {
  console.error('usage: node gltf-validate.js VALIDATOR_PREFIX FILE...');
  process.exit(2);
}
let validator;
try {
  validator = require(path.resolve(process.argv[2], 'node_modules', 'gltf-validator'));
} catch (e) {
  console.error('gltf-validate: the validator is not installed under ' + process.argv[2] +
                ' (scripts/install-gltf-validator.sh): ' + e.message);
  process.exit(2);
}

async function validate(file) {
  const report = await validator.validateBytes(new Uint8Array(fs.readFileSync(file)), {
    uri: file,
    maxIssues: 0,
    // Everything must be embedded: an external resource is an error.
    externalResourceFunction: (uri) => Promise.reject(new Error('external resource ' + uri)),
  });
  const i = report.issues;
  console.log(`${file}: ${i.numErrors} errors, ${i.numWarnings} warnings, ${i.numInfos} infos, ${i.numHints} hints` +
              (report.info ? `, ${report.info.animationCount} animation(s)` : ''));
  for (const m of i.messages) {
    if (m.severity <= 1) console.log(`  ${m.severity === 0 ? 'error' : 'warning'} ${m.code} at ${m.pointer || m.offset}: ${m.message}`);
  }
  return i.numErrors;
}

(async () => {
  let failed = false;
  for (const file of process.argv.slice(3)) {
    try {
      if ((await validate(file)) > 0) failed = true;
    } catch (e) {
      console.log(`${file}: cannot validate: ${e.message || e}`);
      failed = true;
    }
  }
  process.exit(failed ? 1 : 0);
})();
