#!/usr/bin/env node
// Every package in editor/package-lock.json that declares `engines.node` accepts the oldest Node.js the editor
// supports: Debian 12's nodejs 18.20 (tools/install-deps.sh installs it where no node >= 18 is present), so the
// lockfile cannot pull in a Vite 6 or anything else that needs a newer Node than a fresh Debian 12 machine gets.
// usage: node tests/editor/engines.mjs [editor/package-lock.json] [--node 18.20.4]
import fs from 'node:fs';
import path from 'node:path';
import { fileURLToPath } from 'node:url';

const here = path.dirname(fileURLToPath(import.meta.url));
const args = process.argv.slice(2);
const nodeAt = args.indexOf('--node');
const target = (nodeAt >= 0 ? args.splice(nodeAt, 2)[1] : '18.20.4').split('.').map(Number);
const lockFile = args[0] || path.resolve(here, '..', '..', 'editor', 'package-lock.json');

const cmp = (a, b) => {
    for (let i = 0; i < 3; ++i) if ((a[i] ?? 0) !== (b[i] ?? 0)) return (a[i] ?? 0) - (b[i] ?? 0);
    return 0;
};
// "18", "18.2", "18.x", "v18.2.0" -> {v: [18, 2, 0], parts: number of given parts}.
function parseVersion(text) {
    const m = text.replace(/^v/, '').match(/^(\d+|[xX*])(?:\.(\d+|[xX*]))?(?:\.(\d+|[xX*]))?(?:-[\w.]+)?$/);
    if (!m) return null;
    const parts = [m[1], m[2], m[3]].filter(p => p !== undefined && !/^[xX*]$/.test(p)).map(Number);
    return { v: [parts[0] ?? 0, parts[1] ?? 0, parts[2] ?? 0], parts: parts.length };
}
// One comparator of a node-semver range, on version `t`; null when it cannot be read.
function satisfiesComparator(c, t) {
    const m = c.match(/^(>=|<=|>|<|=|\^|~)?\s*(.+)$/);
    if (!m) return null;
    const op = m[1] || '';
    const p = parseVersion(m[2]);
    if (!p) return null;
    const v = p.v;
    const upperOf = n => (n === 0 ? [Infinity] : n === 1 ? [v[0] + 1, 0, 0] : [v[0], v[1] + 1, 0]);
    switch (op) {
    case '>=': return cmp(t, v) >= 0;
    case '>': return p.parts < 3 ? cmp(t, upperOf(p.parts)) >= 0 : cmp(t, v) > 0;
    case '<': return cmp(t, v) < 0;
    case '<=': return p.parts < 3 ? cmp(t, upperOf(p.parts)) < 0 : cmp(t, v) <= 0;
    case '^': {
        const upper = v[0] > 0 || p.parts < 2 ? [v[0] + 1, 0, 0] : v[1] > 0 || p.parts < 3 ? [0, v[1] + 1, 0] : [0, 0, v[2] + 1];
        return cmp(t, v) >= 0 && cmp(t, upper) < 0;
    }
    case '~': return cmp(t, v) >= 0 && cmp(t, p.parts < 2 ? [v[0] + 1, 0, 0] : [v[0], v[1] + 1, 0]) < 0;
    default:
        if (m[2] === '*' || m[2] === '') return true;
        return p.parts < 3 ? cmp(t, v) >= 0 && cmp(t, upperOf(p.parts)) < 0 : cmp(t, v) === 0;
    }
}
// A whole range: alternatives joined by ||, each comparators separated by spaces (or "a - b").
export function satisfies(range, t) {
    return range.split('||').some(alt => {
        alt = alt.trim();
        if (alt === '' || alt === '*') return true;
        const hyphen = alt.match(/^(\S+)\s+-\s+(\S+)$/);
        const comps = hyphen ? [`>=${hyphen[1]}`, `<=${hyphen[2]}`] : alt.replace(/(>=|<=|>|<|=|\^|~)\s+/g, '$1').split(/\s+/);
        let all = true;
        for (const c of comps) {
            const r = satisfiesComparator(c, t);
            if (r === null) throw new Error(`cannot read the range "${range}"`);
            all &&= r;
        }
        return all;
    });
}

const lock = JSON.parse(fs.readFileSync(lockFile, 'utf8'));
if (!lock.packages) {
    console.error(`${lockFile}: no "packages" (lockfileVersion ${lock.lockfileVersion}; npm >= 7 writes version 2 or 3)`);
    process.exit(1);
}
let checked = 0;
const bad = [];
for (const [where, pkg] of Object.entries(lock.packages)) {
    const range = pkg.engines?.node;
    if (!range || pkg.optional) continue; // optional ones (platform binaries) are skipped by npm where they do not fit
    ++checked;
    try {
        if (!satisfies(range, target)) bad.push(`${where || '(the editor)'} ${pkg.version ?? ''}: engines.node "${range}"`);
    } catch (e) {
        bad.push(`${where}: ${e.message}`);
    }
}
// The checker itself, on ranges seen in the wild.
const selfTest = [['^18.0.0 || >=20.0.0', true], ['>=20', false], ['>=18.12', true], ['^20.19.0 || >=22.12.0', false],
                  ['>=14.17', true], ['18 || 20 || >=22', true], ['>= 18', true], ['<18', false], ['^16.14.0 || >=18.0.0', true]];
for (const [range, want] of selfTest)
    if (satisfies(range, [18, 20, 4]) !== want) bad.push(`checker self-test: "${range}" on 18.20.4 should be ${want}`);
console.log(`${lockFile}: ${checked} packages declare engines.node; Node ${target.join('.')} satisfies ` +
            `${checked - bad.filter(b => !b.startsWith('checker')).length}`);
for (const b of bad) console.log(`FAIL ${b}`);
process.exit(bad.length ? 1 : 0);
