// Validates a GLB file with the Khronos glTF validator (npm `gltf-validator`), for
// tests/tests/api/verify_mesh.rs. Usage: node validate.mjs <file.glb>
// Prints the validator's issue counts as one JSON line; exits non-zero when it reports an error
// or a warning.
import { readFileSync } from 'node:fs';
import validator from 'gltf-validator';

const bytes = new Uint8Array(readFileSync(process.argv[2]));
const report = await validator.validateBytes(bytes, { maxIssues: 50 });
const { numErrors, numWarnings, numInfos, numHints, messages } = report.issues;
console.log(JSON.stringify({ numErrors, numWarnings, numInfos, numHints, messages: messages.filter((m) => m.severity <= 1) }));
process.exit(numErrors || numWarnings ? 1 : 0);
