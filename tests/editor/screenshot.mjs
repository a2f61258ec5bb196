#!/usr/bin/env node
// The README's screenshot: the editor with graphs/museum.json open and every thumbnail rendered.
// usage: node tests/editor/screenshot.mjs --vitrine build/vitrine [--source .] [--graph graphs/museum.json]
//                                         [--select grain] [--png docs/editor-museum.png] [--width 1600 --height 1000]
import fs from 'node:fs';
import path from 'node:path';
import { fileURLToPath } from 'node:url';
import { Failure, checkPrerequisites, launchBrowser, makeServedDir, openGraph, parseArgs, selectNode, startServer }
    from './lib.mjs';

const here = path.dirname(fileURLToPath(import.meta.url));
const opts = parseArgs(process.argv.slice(2), { source: path.resolve(here, '..', '..'), graph: 'graphs/museum.json',
                                                select: 'grain', png: 'docs/editor-museum.png', width: '1600',
                                                height: '1000' });
const source = path.resolve(opts.source);
const vitrine = opts.vitrine && path.resolve(opts.vitrine);

async function main() {
    checkPrerequisites(source, vitrine);
    const dir = makeServedDir(source);
    const log = path.join(fs.mkdtempSync('/tmp/vitrine-shot-'), 'server.log');
    const server = await startServer({ vitrine, dir, editorDist: path.join(source, 'editor', 'dist'), logFile: log });
    const browser = await launchBrowser(source);
    try {
        const page = await (await browser.newContext({ viewport: { width: Number(opts.width), height: Number(opts.height) } })).newPage();
        const t0 = Date.now();
        await openGraph(page, server.url, opts.graph, { timeout: 1800000 });
        if (opts.select) await selectNode(page, opts.select);
        await page.waitForTimeout(500);
        await page.screenshot({ path: path.resolve(opts.png) });
        console.log(`${opts.png}: ${(fs.statSync(path.resolve(opts.png)).size / 1024).toFixed(0)} KiB, ` +
                    `${opts.graph} ready after ${((Date.now() - t0) / 1000).toFixed(0)} s`);
    } finally {
        await browser.close().catch(() => {});
        await server.stop();
        fs.rmSync(dir, { recursive: true, force: true });
    }
}

main().catch(e => {
    console.error(`screenshot: ${e instanceof Failure ? e.message : e.stack || e}`);
    process.exitCode = 1;
});
