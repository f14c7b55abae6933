#!/usr/bin/env node
// Validates .glb files with the Khronos glTF validator (tools/node_modules/gltf-validator,
// fetched by scripts/install-deps.sh). Prints each file's counts and every error and
// warning; exits 1 when any file has an error or a warning, 2 when it cannot run.
'use strict';
const fs = require('fs');
const path = require('path');
let validator;
try {
  validator = require(path.join(__dirname, '..', 'tools', 'node_modules', 'gltf-validator'));
} catch (e) {
  console.error('gltf-validate: error: the validator is not installed (run make deps): ' + e.message);
  process.exit(2);
}
(async () => {
  let bad = 0;
  for (const file of process.argv.slice(2)) {
    const report = await validator.validateBytes(new Uint8Array(fs.readFileSync(file)), {maxIssues: 100});
    const i = report.issues;
    console.log(`${file}: ${i.numErrors} errors, ${i.numWarnings} warnings, ${i.numInfos} infos`);
    for (const m of i.messages)
      if (m.severity <= 1) console.log(`  ${m.severity === 0 ? 'error' : 'warning'} ${m.code}: ${m.message} ${m.pointer || ''}`);
    if (i.numErrors || i.numWarnings) bad = 1;
  }
  process.exit(bad);
})().catch((e) => { console.error('gltf-validate: error: ' + e.message); process.exit(2); });
