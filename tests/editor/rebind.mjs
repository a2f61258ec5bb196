#!/usr/bin/env node
// DNS rebinding against `vitrine serve`, in a real browser (issue #27): Debian's headless Chromium, driven by
// playwright-core from editor/node_modules, resolves attacker.test to 127.0.0.1 (--host-resolver-rules), as a DNS
// server under an attacker's control would after the page has loaded (and 127.0.0.1.attacker.test, the name that
// passed the old check). A page from http://attacker.test:PORT/ (the
// server's own port, so that its requests are same-origin for the browser and carry no Origin) then tries to list,
// read and PUT graphs and open the event stream, each time with the access token (as if it had leaked) and without.
// Every request must reach the server and be refused by it (403, reason "host"), and the file on disk must be
// unchanged. A page from another site (http://other.test:PORT2/) trying the same cross-origin must be refused too
// (403 "origin", or the browser keeps it from reading). The same probe from the server's real origin
// (http://127.0.0.1:PORT/, after the ?token= URL set the cookie) must work: that is what shows the probe can tell.
//
// Chromium's own Local Network Access checks would block some of these requests before they reach the server; they
// are turned off here, as other browsers do not have them: the test is of the server's defence, not the browser's.
//
// usage: node tests/editor/rebind.mjs --vitrine build/vitrine [--source .] [--out build/editor-test]
import fs from 'node:fs';
import path from 'node:path';
import { fileURLToPath } from 'node:url';
import { Failure, checkPrerequisites, launchBrowser, makeServedDir, parseArgs, startServer } from './lib.mjs';

const here = path.dirname(fileURLToPath(import.meta.url));
const opts = parseArgs(process.argv.slice(2), { source: path.resolve(here, '..', '..'), out: 'editor-test' });
const source = path.resolve(opts.source);
const out = path.resolve(opts.out);
const vitrine = opts.vitrine && path.resolve(opts.vitrine);
const GRAPH = 'graphs/fxaa_zoneplate.json';

let passed = 0;
const failed = [];
function check(ok, what) {
    if (ok) ++passed;
    else {
        failed.push(what);
        console.log(`FAIL: ${what}`);
    }
}

// Runs in the page: list, read, PUT (GRAPH with `marker` as its description) and the event stream, against BASE
// ("" for the page's own origin). Each answer as {status, reason, body} or {error} when fetch itself failed.
async function probe({ base, token, graph, marker }) {
    const auth = token ? { Authorization: `token ${token}` } : {};
    const results = {};
    const attempt = async (name, url, init = {}) => {
        try {
            const controller = new AbortController();
            const timer = setTimeout(() => controller.abort(), 10000);
            const res = await fetch(base + url, { ...init, signal: controller.signal, credentials: 'include' });
            const type = res.headers.get('Content-Type') || '';
            // The event stream's body never ends: only its status is read.
            const body = type.startsWith('text/event-stream') ? '(stream)' : await res.text();
            clearTimeout(timer);
            controller.abort();
            let reason = null;
            let graphs = null;
            try {
                const parsed = JSON.parse(body);
                reason = parsed.reason ?? null;
                if (Array.isArray(parsed.graphs)) graphs = parsed.graphs.map(g => g.path);
            } catch {
                /* not JSON */
            }
            results[name] = { status: res.status, reason, graphs, body: body.slice(0, 200) };
        } catch (e) {
            results[name] = { error: String(e) };
        }
    };
    const doc = { description: marker, nodes: {}, outputs: {} };
    await attempt('list', '/api/graphs', { headers: auth });
    await attempt('read', `/api/graphs/${graph}`, { headers: auth });
    await attempt('put', `/api/graphs/${graph}`,
                  { method: 'PUT', headers: { ...auth, 'Content-Type': 'application/json' }, body: JSON.stringify(doc) });
    await attempt('events', `/api/events${token ? `?token=${token}` : ''}`);
    // EventSource, as the editor opens it: "open" or "error" within 10 s.
    results.eventsource = await new Promise(resolve => {
        const s = new EventSource(`${base}/api/events${token ? `?token=${token}` : ''}`, { withCredentials: true });
        const timer = setTimeout(() => {
            s.close();
            resolve('timeout');
        }, 10000);
        s.onopen = () => {
            clearTimeout(timer);
            s.close();
            resolve('open');
        };
        s.onerror = () => {
            clearTimeout(timer);
            s.close();
            resolve('error');
        };
    });
    return results;
}

async function main() {
    checkPrerequisites(source, vitrine);
    fs.mkdirSync(out, { recursive: true });
    const dir = makeServedDir(source);
    const file = path.join(dir, GRAPH);
    const original = fs.readFileSync(file);
    const server = await startServer({ vitrine, dir, editorDist: path.join(source, 'editor', 'dist'),
                                       logFile: path.join(out, 'rebind-server.log'), extraArgs: ['--validate'] });
    const port = new URL(server.url).port;
    console.log(`rebinding test: vitrine serve at ${server.url}`);
    const browser = await launchBrowser(source, [
        '--host-resolver-rules=MAP attacker.test 127.0.0.1, MAP 127.0.0.1.attacker.test 127.0.0.1, MAP other.test 127.0.0.1',
        '--disable-features=LocalNetworkAccessChecks,PrivateNetworkAccessRespectPreflightResults,' +
            'BlockInsecurePrivateNetworkRequests,PrivateNetworkAccessSendPreflights',
    ]);
    try {
        const context = await browser.newContext();
        const page = await context.newPage();
        const marker = 'REBOUND-' + Date.now();

        // The real origin first, so that the browser holds the token's cookie (for 127.0.0.1) while the attacker's
        // page tries.
        await page.goto(`${server.url}?token=${server.token}`);
        const own = await page.evaluate(probe, { base: '', token: null, graph: GRAPH, marker: 'own' });
        console.log('from the real origin:', JSON.stringify(own).slice(0, 600));
        check(own.list?.status === 200 && (own.list.graphs || []).includes(GRAPH),
              `real origin: list works (${own.list?.status}, ${own.list?.graphs})`);
        check(own.read?.status === 200 && own.read.body.includes('vitrine-graph/1'), `real origin: read works (${own.read?.status})`);
        check(own.put?.status === 200 && fs.readFileSync(file, 'utf8').includes('"own"'),
              `real origin: PUT works and writes the file (${own.put?.status} ${own.put?.body})`);
        check(own.events?.status === 200 && own.eventsource === 'open',
              `real origin: the event stream opens (${own.events?.status}, EventSource ${own.eventsource})`);
        fs.writeFileSync(file, original);
        const before = fs.readFileSync(file);

        // The attacker's page at http://NAME:PORT/ (fulfilled by the test: the attacker's own server answered it
        // before the name was rebound); its requests go over the network to 127.0.0.1. 127.0.0.1.attacker.test is
        // the name that got through the old check (a Host starting with "127.").
        for (const name of ['attacker.test', '127.0.0.1.attacker.test']) {
            const evil = `http://${name}:${port}/`;
            await page.route(`${evil}evil.html`, route =>
                route.fulfill({ status: 200, contentType: 'text/html', body: '<!doctype html><title>cat pictures</title>' }));
            await page.goto(`${evil}evil.html`);
            for (const token of [null, server.token]) {
                const got = await page.evaluate(probe, { base: '', token, graph: GRAPH, marker });
                const how = `${name}, ${token ? 'with the leaked token' : 'without the token'}`;
                console.log(`rebound page ${how}:`, JSON.stringify(got).slice(0, 400));
                for (const what of ['list', 'read', 'put', 'events'])
                    check(got[what]?.status === 403 && got[what].reason === 'host',
                          `rebound page ${how}: ${what} refused by the server with 403 "host" (${JSON.stringify(got[what])})`);
                check(got.eventsource === 'error', `rebound page ${how}: EventSource does not open (${got.eventsource})`);
                check(!JSON.stringify(got).includes('vitrine-graph/1') && !got.list?.graphs,
                      `rebound page ${how}: no graph name or content came back`);
            }
        }
        check(fs.readFileSync(file).equals(before), 'rebound page: the graph file is unchanged');

        // Another site's page (a different origin) calling the real address: Origin is checked, the SameSite
        // cookie stays home.
        const other = `http://other.test:${Number(port) === 65535 ? 1 : Number(port) + 1}/`;
        await page.route(`${other}page.html`, route =>
            route.fulfill({ status: 200, contentType: 'text/html', body: '<!doctype html><title>other</title>' }));
        await page.goto(`${other}page.html`);
        const cross = await page.evaluate(probe, { base: server.url.replace(/\/$/, ''), token: null, graph: GRAPH, marker });
        console.log('another site, cross-origin:', JSON.stringify(cross));
        for (const name of ['list', 'read', 'put', 'events']) {
            const r = cross[name] || {};
            // Refused by the server (403 origin, readable if it sent CORS headers, which it does not), or the browser
            // kept the page from reading the answer (a TypeError): either way nothing came back.
            check((r.status === 403 && r.reason === 'origin') || (r.error && /TypeError|Failed to fetch/.test(r.error)),
                  `another site: ${name} refused (${JSON.stringify(r)})`);
        }
        check(cross.eventsource === 'error', `another site: EventSource does not open (${cross.eventsource})`);
        check(fs.readFileSync(file).equals(before), 'another site: the graph file is unchanged');
        await page.screenshot({ path: path.join(out, 'rebind.png') });
        await context.close();
    } finally {
        await browser.close().catch(() => {});
        const stopped = await server.stop();
        check(stopped.code === 0, `the server stops cleanly (${JSON.stringify(stopped)})`);
        fs.rmSync(dir, { recursive: true, force: true });
    }
    console.log(`rebinding tests: ${passed} passed, ${failed.length} failed`);
    process.exitCode = failed.length ? 1 : 0;
}

main().catch(e => {
    console.error(`rebinding tests: ${e instanceof Failure ? e.message : e.stack || e}`);
    process.exitCode = 1;
});
