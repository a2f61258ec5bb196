// Runs the Khronos glTF-Validator on each file named on the command line with no cap on messages (maxIssues 0)
// and prints its summary per file (errors, warnings, infos, hints) and every message at or above --show (default
// all). Exits 1 when any file has an error or a warning (or, with --no-infos, an info), 2 on a usage error or a file
// the validator cannot read. External buffers and images resolve relative to each file.
// Usage: node tools/gltf-validator/validate.mjs [--no-infos] FILE...
import { readFile } from 'node:fs/promises';
import path from 'node:path';
import { createRequire } from 'node:module';

const require = createRequire(import.meta.url);
let validator;
try {
    validator = require('gltf-validator');
} catch (e) {
    console.error('validate.mjs: the npm package gltf-validator is not installed in tools/gltf-validator/node_modules; ' +
                  'run tools/install-deps.sh (npm ci from the committed package-lock.json)');
    process.exit(2);
}

const args = process.argv.slice(2);
const noInfos = args.includes('--no-infos');
const files = args.filter((a) => !a.startsWith('--'));
if (files.length === 0) {
    console.error('usage: node tools/gltf-validator/validate.mjs [--no-infos] FILE.gltf|FILE.glb...');
    process.exit(2);
}
const severities = ['error', 'warning', 'info', 'hint'];
let failed = false;
for (const file of files) {
    let bytes;
    try {
        bytes = await readFile(file);
    } catch (e) {
        console.error(`${file}: cannot read: ${e.message}`);
        process.exit(2);
    }
    let report;
    try {
        report = await validator.validateBytes(new Uint8Array(bytes), {
            uri: path.basename(file),
            maxIssues: 0, // no cap: every message
            externalResourceFunction: (uri) =>
                readFile(path.resolve(path.dirname(file), decodeURIComponent(uri))).then((b) => new Uint8Array(b)),
        });
    } catch (e) {
        console.error(`${file}: the validator could not read it: ${e}`);
        process.exit(2);
    }
    const i = report.issues;
    console.log(`${file}: ${i.numErrors} errors, ${i.numWarnings} warnings, ${i.numInfos} infos, ${i.numHints} hints` +
                (i.truncated ? ' (TRUNCATED)' : ''));
    for (const m of i.messages)
        console.log(`  ${severities[m.severity] ?? m.severity} ${m.code} at ${m.pointer ?? m.offset ?? ''}: ${m.message}`);
    if (i.numErrors > 0 || i.numWarnings > 0 || (noInfos && i.numInfos > 0) || i.truncated) failed = true;
}
process.exit(failed ? 1 : 0);
