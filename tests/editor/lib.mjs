// Shared by the editor's browser tests (run.mjs), measurements (measure.mjs) and the README screenshot
// (screenshot.mjs): `vitrine serve` on a loopback port it picks over a temporary copy of graphs/ and data/, Debian's
// headless Chromium driven by playwright-core from editor/node_modules (never a downloaded browser), and helpers
// that drive the editor through the data-testids of editor/TESTING.md.
import { spawn } from 'node:child_process';
import fs from 'node:fs';
import { createRequire } from 'node:module';
import os from 'node:os';
import path from 'node:path';

export class Failure extends Error {}

export function fail(message) {
    throw new Failure(message);
}

// --name value options; bare --flag is true.
export function parseArgs(argv, defaults) {
    const opts = { ...defaults };
    for (let i = 0; i < argv.length; ++i) {
        const a = argv[i];
        if (!a.startsWith('--')) fail(`unexpected argument ${a}`);
        const key = a.slice(2);
        if (i + 1 < argv.length && !argv[i + 1].startsWith('--')) opts[key] = argv[++i];
        else opts[key] = true;
    }
    return opts;
}

// Everything the tests need, checked up front so that a missing piece is one clear message, never a skip.
export function checkPrerequisites(source, vitrine) {
    const editor = path.join(source, 'editor');
    const problems = [];
    if (!vitrine || !fs.existsSync(vitrine)) problems.push(`no vitrine binary at ${vitrine} (build it: cmake --build build)`);
    if (!fs.existsSync(path.join(editor, 'node_modules', 'playwright-core')))
        problems.push('editor/node_modules/playwright-core is missing (run tools/install-deps.sh: npm ci in editor/)');
    if (!fs.existsSync(path.join(editor, 'dist', 'index.html')))
        problems.push('editor/dist/index.html is missing: the editor is not built (cmake --build build builds it ' +
                      'once editor/node_modules is installed)');
    const browser = chromiumPath();
    if (!fs.existsSync(browser)) problems.push(`no Chromium at ${browser} (tools/install-deps.sh installs Debian's chromium)`);
    if (problems.length) fail('cannot run the editor tests:\n  ' + problems.join('\n  '));
}

export function chromiumPath() {
    return process.env.VITRINE_CHROMIUM || '/usr/bin/chromium';
}

// A temporary directory holding copies of the repository's graphs/ and data/: the server reads and writes there,
// never in the source tree.
export function makeServedDir(source) {
    const dir = fs.mkdtempSync(path.join(os.tmpdir(), 'vitrine-editor-test-'));
    for (const sub of ['graphs', 'data']) fs.cpSync(path.join(source, sub), path.join(dir, sub), { recursive: true, dereference: true });
    return dir;
}

export function resetGraphs(source, dir) {
    fs.rmSync(path.join(dir, 'graphs'), { recursive: true, force: true });
    fs.cpSync(path.join(source, 'graphs'), path.join(dir, 'graphs'), { recursive: true, dereference: true });
}

const children = new Set();
function killChildren() {
    for (const c of children) if (c.exitCode === null && c.signalCode === null) c.kill('SIGKILL');
}
process.on('exit', killChildren);
for (const sig of ['SIGINT', 'SIGTERM', 'SIGHUP'])
    process.on(sig, () => {
        killChildren();
        process.exit(130);
    });

// The access token of the server startServer started last (vitrine serve asks for one on the loopback too):
// openGraph passes it in the URL, the page keeps it as a cookie.
let serverToken = null;

// Starts `vitrine serve DIR --port 0` and reads the URL it prints ("vitrine serve: listening on
// http://H:P/?token=T"): `url` is http://H:P/, `token` T. Its stdout and stderr go to logFile.
export async function startServer({ vitrine, dir, editorDist, logFile, extraArgs = [] }) {
    const log = fs.createWriteStream(logFile);
    const proc = spawn(vitrine, ['serve', dir, '--port', '0', '--editor', editorDist, ...extraArgs],
                       { stdio: ['ignore', 'pipe', 'pipe'] });
    children.add(proc);
    let text = '';
    const url = await new Promise((resolve, reject) => {
        const timer = setTimeout(() => reject(new Failure(`vitrine serve printed no URL within 120 s:\n${text}`)), 120000);
        const onData = chunk => {
            log.write(chunk);
            text += chunk.toString();
            const m = text.match(/listening on (http:\/\/[^\s]+\/)(\?token=\w+)?/);
            if (m) {
                clearTimeout(timer);
                serverToken = m[2] ? m[2].slice('?token='.length) : null;
                resolve(m[1]);
            }
        };
        proc.stdout.on('data', onData);
        proc.stderr.on('data', onData);
        proc.on('exit', code => {
            clearTimeout(timer);
            reject(new Failure(`vitrine serve exited (status ${code}) before listening:\n${text}`));
        });
    });
    proc.stdout.removeAllListeners('data');
    proc.stderr.removeAllListeners('data');
    proc.stdout.on('data', c => log.write(c));
    proc.stderr.on('data', c => log.write(c));
    const exited = new Promise(resolve => proc.on('exit', (code, signal) => resolve({ code, signal })));
    return {
        url,
        token: serverToken,
        pid: proc.pid,
        alive: () => proc.exitCode === null && proc.signalCode === null,
        // SIGTERM, then SIGKILL after 60 s; the exit status.
        async stop() {
            if (proc.exitCode !== null || proc.signalCode !== null) return { code: proc.exitCode, signal: proc.signalCode };
            proc.kill('SIGTERM');
            const timer = setTimeout(() => proc.kill('SIGKILL'), 60000);
            const result = await exited;
            clearTimeout(timer);
            children.delete(proc);
            log.end();
            return result;
        },
    };
}

// Extra command-line switches for Chromium in `args` (the rebinding test's --host-resolver-rules).
export async function launchBrowser(source, args = []) {
    const require = createRequire(path.join(source, 'editor', 'package.json'));
    const { chromium } = require('playwright-core');
    return chromium.launch({
        executablePath: chromiumPath(),
        headless: true,
        // Root has no user namespaces for the sandbox; the pages are our own, on the loopback.
        args: ['--no-sandbox', '--disable-dev-shm-usage', '--disable-gpu', ...args],
    });
}

export const tid = id => `[data-testid="${id}"]`;

// Waits until fn() (run in this process) returns a truthy value; fails with what() after timeout ms.
export async function poll(fn, what, timeout = 30000, interval = 100) {
    const end = Date.now() + timeout;
    let last;
    for (;;) {
        try {
            last = await fn();
            if (last) return last;
        } catch (e) {
            last = e;
        }
        if (Date.now() > end) fail(`${typeof what === 'function' ? await what(last) : what} (waited ${timeout / 1000} s)`);
        await new Promise(r => setTimeout(r, interval));
    }
}

export async function waitVisible(page, id, what, timeout = 30000) {
    try {
        await page.locator(tid(id)).first().waitFor({ state: 'visible', timeout });
    } catch {
        fail(`${what}: no visible [data-testid="${id}"] after ${timeout / 1000} s`);
    }
}

export async function waitIdle(page, timeout = 180000) {
    try {
        await page.waitForFunction(() => {
            const app = document.querySelector('[data-testid="app"]');
            return app && app.dataset.state === 'idle';
        }, null, { timeout, polling: 100 });
    } catch {
        const state = await page.locator(tid('app')).getAttribute('data-state').catch(() => null);
        fail(`the editor did not become idle within ${timeout / 1000} s (app data-state=${state})`);
    }
}

// Opens FILE (relative to the served directory) through the ?graph= URL and waits until it is drawn and idle.
export async function openGraph(page, url, file, { idle = true, timeout = 180000 } = {}) {
    const token = serverToken ? `&token=${serverToken}` : '';
    await page.goto(`${url}?graph=${encodeURIComponent(file)}${token}`);
    await waitVisible(page, 'app', `opening ${file}`, 30000);
    await poll(async () => ((await page.locator(tid('current-file')).textContent()) || '').includes(file),
               async () => `opening ${file}: current-file shows "${await page.locator(tid('current-file')).textContent().catch(() => '?')}"`,
               60000);
    if (idle) await waitIdle(page, timeout);
}

export async function nodeNames(page) {
    return page.$$eval('[data-testid^="node-"]', els => els.map(e => e.dataset.testid.slice(5))
                                                         .filter(n => !n.startsWith('error-')));
}

export async function edgeCount(page) {
    return page.locator('.react-flow__edge').count();
}

// Pans the canvas (dragging empty background, as a user does) until node NAME is inside it.
export async function bringIntoView(page, name) {
    const node = page.locator(tid(`node-${name}`));
    for (let k = 0; k < 8; ++k) {
        const c = await page.locator('.react-flow').first().boundingBox();
        const b = await node.boundingBox();
        if (!c || !b) fail(`node ${name} or the canvas has no box on the page`);
        const m = 20;
        if (b.x >= c.x + m && b.y >= c.y + m && b.x + Math.min(b.width, 200) <= c.x + c.width - m &&
            b.y + Math.min(b.height, 60) <= c.y + c.height - m) return;
        const clamp = (v, r) => Math.max(-r, Math.min(r, v));
        const dx = clamp(c.x + c.width / 2 - (b.x + Math.min(b.width, 200) / 2), c.width / 2 - 40);
        const dy = clamp(c.y + c.height / 2 - (b.y + Math.min(b.height, 60) / 2), c.height / 2 - 40);
        // An empty spot of the pane from which the drag stays inside the canvas.
        const start = await page.evaluate(([c, dx, dy]) => {
            for (let gy = 0.1; gy < 0.95; gy += 0.05)
                for (let gx = 0.1; gx < 0.95; gx += 0.05) {
                    const x = c.x + gx * c.width, y = c.y + gy * c.height;
                    if (x + dx < c.x + 10 || x + dx > c.x + c.width - 10 || y + dy < c.y + 10 || y + dy > c.y + c.height - 10) continue;
                    const e = document.elementFromPoint(x, y);
                    if (e && e.classList.contains('react-flow__pane')) return { x, y };
                }
            return null;
        }, [c, dx, dy]);
        if (!start) fail(`cannot pan node ${name} into view: no empty background to drag`);
        await page.mouse.move(start.x, start.y);
        await page.mouse.down();
        await page.mouse.move(start.x + dx, start.y + dy, { steps: 10 });
        await page.mouse.up();
        await page.waitForTimeout(200);
    }
    fail(`node ${name} is still outside the canvas after panning`);
}

// Selects a node by clicking its title strip (not its thumbnail, which opens the viewer).
export async function selectNode(page, name) {
    const node = page.locator(tid(`node-${name}`));
    await node.waitFor({ state: 'visible', timeout: 30000 }).catch(() => fail(`no node ${name} on the canvas`));
    await bringIntoView(page, name);
    // 12 x 6 px into the title strip at 100 % zoom; proportionally less on a zoomed-out canvas.
    const b = await node.boundingBox();
    if (!b) fail(`node ${name} has no box on the page`);
    await page.mouse.click(b.x + Math.min(12, b.width * 0.06), b.y + Math.min(6, b.height * 0.035));
    await poll(async () => (await page.locator(tid('inspector-name')).textContent().catch(() => '')).trim() === name,
               async () => `clicking node ${name}: inspector-name shows "${await page.locator(tid('inspector-name')).textContent().catch(() => 'nothing')}"`,
               10000);
}

// Types VALUE into the param's entry (or picks it from a select, or ticks a checkbox) and commits it.
export async function setParam(page, node, key, value) {
    const input = page.locator(tid(`param-${node}-${key}`)).first();
    await input.waitFor({ state: 'visible', timeout: 10000 })
        .catch(() => fail(`no visible param entry [data-testid="param-${node}-${key}"] in the inspector`));
    const kind = await input.evaluate(e => `${e.tagName.toLowerCase()}:${e.type || ''}`);
    if (kind.startsWith('select')) await input.selectOption(String(value));
    else if (kind === 'input:checkbox') await input.setChecked(Boolean(value));
    else {
        await input.fill(String(value));
        await input.press('Enter');
    }
}

export async function previewInfo(page, id) {
    return page.locator(tid(id)).first().evaluate(e => ({
        state: e.dataset.state, version: Number(e.dataset.version), src: e.getAttribute('src'),
        complete: e.complete, width: e.naturalWidth, height: e.naturalHeight,
    })).catch(() => null);
}

// Waits until thumbnail ID holds a decoded image newer than version `after` (-1: any) and is "ready".
export async function waitPreview(page, id, after = -1, timeout = 180000) {
    try {
        await page.waitForFunction(([id, after]) => {
            const e = document.querySelector(`[data-testid="${id}"]`);
            return e && e.dataset.state === 'ready' && Number(e.dataset.version) > after && e.complete &&
                e.naturalWidth > 0;
        }, [id, after], { timeout, polling: 50 });
    } catch {
        const info = await previewInfo(page, id);
        fail(`thumbnail ${id}: no new ready image (version > ${after}) within ${timeout / 1000} s; now ${JSON.stringify(info)}`);
    }
    return previewInfo(page, id);
}

// The thumbnail's pixels, read back through a canvas in the page: {width, height, data: [r, g, b, a, ...]}.
export async function thumbnailPixels(page, id) {
    return page.locator(tid(id)).first().evaluate(async img => {
        if (img.decode) await img.decode().catch(() => {});
        const c = document.createElement('canvas');
        c.width = img.naturalWidth;
        c.height = img.naturalHeight;
        const ctx = c.getContext('2d');
        ctx.drawImage(img, 0, 0);
        return { width: c.width, height: c.height, data: Array.from(ctx.getImageData(0, 0, c.width, c.height).data) };
    });
}

// Mean |a - b| over RGB (0..255) and the share of pixels whose largest channel difference exceeds 8.
export function pixelDifference(a, b) {
    if (a.width !== b.width || a.height !== b.height)
        return { sizeDiffers: true, mean: Infinity, changed: 1 };
    let sum = 0, changed = 0;
    for (let i = 0; i < a.data.length; i += 4) {
        let m = 0;
        for (let c = 0; c < 3; ++c) {
            const d = Math.abs(a.data[i + c] - b.data[i + c]);
            sum += d;
            m = Math.max(m, d);
        }
        if (m > 8) ++changed;
    }
    const pixels = a.data.length / 4;
    return { mean: sum / (3 * pixels), changed: changed / pixels };
}

// Drags from handle FROM ("out-node-port") to handle TO ("in-node-port") with the mouse, as a user does.
export async function connect(page, from, to) {
    const boxOf = async id => {
        const h = page.locator(tid(id)).first();
        await h.waitFor({ state: 'attached', timeout: 10000 }).catch(() => fail(`no handle [data-testid="${id}"]`));
        // Nodes change size while their thumbnails load: wait until the handle stays put.
        let b = await h.boundingBox();
        for (let i = 0; i < 50; ++i) {
            await page.waitForTimeout(100);
            const c = await h.boundingBox();
            if (b && c && b.x === c.x && b.y === c.y) break;
            b = c;
        }
        if (!b) fail(`handle ${id} is not visible`);
        return { x: b.x + b.width / 2, y: b.y + b.height / 2 };
    };
    await waitIdle(page, 180000);
    const a = await boxOf(from);
    const b = await boxOf(to);
    // A handle under another node cannot be reached by a user either: say so instead of dropping elsewhere.
    for (const [id, p] of [[from, a], [to, b]]) {
        const top = await page.evaluate(([id, x, y]) => {
            const e = document.elementFromPoint(x, y);
            if (!e) return 'nothing';
            if (e.closest(`[data-testid="${id}"]`)) return null;
            const node = e.closest('[data-testid^="node-"]');
            return node ? `node ${node.dataset.testid.slice(5)}` : `<${e.tagName.toLowerCase()} class="${e.className}">`;
        }, [id, p.x, p.y]);
        if (top) fail(`handle ${id} is covered by ${top} at (${Math.round(p.x)}, ${Math.round(p.y)}): it cannot be dragged from or onto`);
    }
    await page.mouse.move(a.x, a.y);
    await page.mouse.down();
    await page.mouse.move((a.x + b.x) / 2, (a.y + b.y) / 2, { steps: 8 });
    await page.mouse.move(b.x, b.y, { steps: 8 });
    await page.mouse.up();
}

// Drags node NAME by its title strip to empty canvas below every node, as a user makes room for it.
export async function moveNodeToFreeSpace(page, name) {
    const boxes = await page.$$eval('.react-flow__node', els => els.map(e => {
        const r = e.getBoundingClientRect();
        return { id: e.querySelector('[data-testid^="node-"]')?.dataset.testid || e.dataset.testid, x: r.x, y: r.y, w: r.width, h: r.height };
    }));
    const me = boxes.find(b => b.id === `node-${name}`);
    if (!me) fail(`no node ${name} to move`);
    const others = boxes.filter(b => b !== me);
    const left = Math.min(...others.map(b => b.x));
    const bottom = Math.max(...others.map(b => b.y + b.h));
    await page.mouse.move(me.x + 12, me.y + 6);
    await page.mouse.down();
    await page.mouse.move(left + 12, bottom + 40 + 6, { steps: 10 });
    await page.mouse.up();
}

// Zooms the canvas in by STEPS wheel notches around node NAME (React Flow zooms about the cursor).
export async function zoomAt(page, name, steps) {
    await bringIntoView(page, name);
    const b = await page.locator(tid(`node-${name}`)).boundingBox();
    if (!b) fail(`no node ${name} to zoom at`);
    await page.mouse.move(b.x + b.width / 2, b.y + b.height / 2);
    for (let i = 0; i < steps; ++i) {
        await page.mouse.wheel(0, -100);
        await page.waitForTimeout(150);
    }
    await page.waitForTimeout(500);
}

// Deletes a node: the delete-node button when there is one, else the Delete key, on the selected node.
export async function deleteNode(page, name) {
    await selectNode(page, name);
    const button = page.locator(tid('delete-node'));
    if (await button.count() && await button.first().isVisible()) await button.first().click();
    else await page.keyboard.press('Delete');
    await poll(async () => (await page.locator(tid(`node-${name}`)).count()) === 0,
               `deleting node ${name}: it is still on the canvas`, 10000);
}

// Deep JSON equality, ignoring key order; returns the JSON pointer of the first difference or null.
export function jsonDiff(a, b, pointer = '') {
    if (a === b) return null;
    if (typeof a !== typeof b || a === null || b === null || Array.isArray(a) !== Array.isArray(b))
        return pointer || '/';
    if (typeof a !== 'object') return pointer || '/';
    if (Array.isArray(a)) {
        if (a.length !== b.length) return pointer || '/';
        for (let i = 0; i < a.length; ++i) {
            const d = jsonDiff(a[i], b[i], `${pointer}/${i}`);
            if (d) return d;
        }
        return null;
    }
    const keys = new Set([...Object.keys(a), ...Object.keys(b)]);
    for (const k of keys) {
        if (!(k in a) || !(k in b)) return `${pointer}/${k}`;
        const d = jsonDiff(a[k], b[k], `${pointer}/${k}`);
        if (d) return d;
    }
    return null;
}

export function readJson(file) {
    const text = fs.readFileSync(file, 'utf8');
    try {
        return JSON.parse(text);
    } catch (e) {
        fail(`${file} is not valid JSON: ${e.message}`);
    }
}

// The resident set of process PID in KiB (/proc/PID/status VmRSS).
export function rssKiB(pid) {
    const m = fs.readFileSync(`/proc/${pid}/status`, 'utf8').match(/VmRSS:\s+(\d+)\s+kB/);
    return m ? Number(m[1]) : NaN;
}
