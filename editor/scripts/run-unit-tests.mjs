// `npm test`: compiles the document logic (src/graph) and test/*.test.ts with tsc, then runs them with Node's
// own test runner (node --test, Node >= 18). No browser, no server.
import { execFileSync } from 'node:child_process';
import { mkdirSync, readdirSync, rmSync, writeFileSync } from 'node:fs';
import { dirname, join } from 'node:path';
import { fileURLToPath } from 'node:url';

const root = join(dirname(fileURLToPath(import.meta.url)), '..');
const out = join(root, '.test-build');
rmSync(out, { recursive: true, force: true });
execFileSync(process.execPath, [join(root, 'node_modules/typescript/bin/tsc'), '-p', join(root, 'tsconfig.test.json')], {
  stdio: 'inherit',
});
mkdirSync(out, { recursive: true });
writeFileSync(join(out, 'package.json'), '{"type": "commonjs"}\n');
const tests = readdirSync(join(out, 'test'))
  .filter((f) => f.endsWith('.test.js'))
  .map((f) => join(out, 'test', f));
execFileSync(process.execPath, ['--test', ...tests], { stdio: 'inherit', cwd: root });
