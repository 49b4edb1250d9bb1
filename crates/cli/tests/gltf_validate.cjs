// Validates .glb files with the Khronos glTF-Validator (npm package gltf-validator), installed by
// .ci/run under target/gltf-validator. Usage: node gltf_validate.cjs VALIDATOR_DIR FILE...
// Prints one JSON line per file: {file, errors, warnings, infos, messages}.
const fs = require('fs');
const path = require('path');
const validator = require(path.join(process.argv[2], 'node_modules', 'gltf-validator'));
(async () => {
  for (const file of process.argv.slice(3)) {
    const report = await validator.validateBytes(new Uint8Array(fs.readFileSync(file)), {
      maxIssues: 100,
    });
    const i = report.issues;
    console.log(JSON.stringify({
      file, errors: i.numErrors, warnings: i.numWarnings, infos: i.numInfos,
      messages: i.messages.slice(0, 10).map((m) => `${m.code} ${m.pointer || ''}: ${m.message}`),
    }));
  }
})().catch((e) => { console.error(e); process.exit(1); });
