#!/usr/bin/env node
// Measurements of the graph editor for issue 13's closing note (not a ctest: timings are reported, not asserted):
//  1. time from a param change to an updated preview thumbnail, for graphs/fxaa_zoneplate.json (fxaa.subpix ->
//     tonemap's thumbnail) and graphs/museum.json (ao.intensity -> the final grain thumbnail; grain.strength ->
//     the same), at the editor's preview size, on whatever Vulkan device the server picks (lavapipe here);
//  2. the server's resident memory (/proc/PID/status VmRSS) every 10 of 100 edits of fxaa_zoneplate, and with
//     --museum-edits N every 10 of N edits of the museum's grain.strength (each waits for the final thumbnail);
//  3. the size of editor/dist (raw and gzip).
// The time includes the editor's debounce (about 300 ms) and the PNG's transfer and decoding: what a user waits.
//
// usage: node tests/editor/measure.mjs --vitrine build/vitrine [--source .] [--out build/editor-measure]
//                                      [--repeat 5] [--edits 100] [--skip zoneplate,museum] [--museum-edits 0]
//                                      [--warm N] (the server's --warm)
import fs from 'node:fs';
import path from 'node:path';
import zlib from 'node:zlib';
import { fileURLToPath } from 'node:url';
import {
    Failure, checkPrerequisites, launchBrowser, makeServedDir, openGraph, parseArgs, previewInfo, rssKiB,
    selectNode, setParam, startServer, waitIdle, waitPreview, zoomAt,
} from './lib.mjs';

const here = path.dirname(fileURLToPath(import.meta.url));
const opts = parseArgs(process.argv.slice(2), { source: path.resolve(here, '..', '..'), out: 'editor-measure',
                                                repeat: '5', edits: '100', skip: '', 'museum-edits': '0' });
const source = path.resolve(opts.source);
const out = path.resolve(opts.out);
const vitrine = opts.vitrine && path.resolve(opts.vitrine);
const skip = String(opts.skip).split(',');
const results = {};

const median = xs => [...xs].sort((a, b) => a - b)[Math.floor(xs.length / 2)];
const stats = xs => ({ median_ms: median(xs), min_ms: Math.min(...xs), max_ms: Math.max(...xs), samples_ms: xs });

// Sets NODE.KEY to each of VALUES in turn; the ms from the change to a new ready image in thumbnail PREVIEW.
async function timeEdits(page, node, key, values, preview, timeout = 600000) {
    await selectNode(page, node);
    const times = [];
    for (const v of values) {
        const before = (await previewInfo(page, preview)).version;
        const t0 = performance.now();
        await setParam(page, node, key, v);
        await waitPreview(page, preview, before, timeout);
        times.push(Math.round(performance.now() - t0));
        console.log(`  ${node}.${key} = ${v}: ${preview} updated after ${times.at(-1)} ms`);
        await waitIdle(page, timeout); // the next edit starts from a quiet editor
    }
    return times;
}

function bundleSize() {
    const dist = path.join(source, 'editor', 'dist');
    let raw = 0, gz = 0;
    const files = [];
    const walk = d => {
        for (const e of fs.readdirSync(d, { withFileTypes: true })) {
            const p = path.join(d, e.name);
            if (e.isDirectory()) walk(p);
            else {
                const data = fs.readFileSync(p);
                const g = zlib.gzipSync(data, { level: 9 }).length;
                raw += data.length;
                gz += g;
                files.push({ file: path.relative(dist, p), bytes: data.length, gzip_bytes: g });
            }
        }
    };
    walk(dist);
    return { bytes: raw, gzip_bytes: gz, files };
}

async function main() {
    checkPrerequisites(source, vitrine);
    fs.mkdirSync(out, { recursive: true });
    results.bundle = bundleSize();
    console.log(`editor/dist: ${(results.bundle.bytes / 1024).toFixed(1)} KiB, gzip ${(results.bundle.gzip_bytes / 1024).toFixed(1)} KiB`);

    const dir = makeServedDir(source);
    const server = await startServer({ vitrine, dir, editorDist: path.join(source, 'editor', 'dist'),
                                       logFile: path.join(out, 'server.log'),
                                       extraArgs: typeof opts.warm === 'string' ? ['--warm', opts.warm] : [] });
    console.log(`vitrine serve at ${server.url} (pid ${server.pid})`);
    const browser = await launchBrowser(source);
    try {
        const page = await (await browser.newContext({ viewport: { width: 1600, height: 1000 } })).newPage();
        const n = Number(opts.repeat);
        const subpix = Array.from({ length: n }, (_, i) => [0, 0.25, 0.5, 1][i % 4]);

        if (!skip.includes('zoneplate')) {
        console.log('fxaa_zoneplate.json: fxaa.subpix -> preview-tonemap-color');
        await openGraph(page, server.url, 'graphs/fxaa_zoneplate.json', { timeout: 600000 });
        const size = await previewInfo(page, 'preview-tonemap-color');
        results.zoneplate = { preview: `${size.width}x${size.height}`,
                              ...stats(await timeEdits(page, 'fxaa', 'subpix', subpix, 'preview-tonemap-color')) };

        const edits = Number(opts.edits);
        console.log(`server VmRSS over ${edits} edits of fxaa.subpix (each waits for the tonemap thumbnail)`);
        const rss = [{ edits: 0, kib: rssKiB(server.pid) }];
        await selectNode(page, 'fxaa');
        for (let i = 1; i <= edits; ++i) {
            const before = (await previewInfo(page, 'preview-tonemap-color')).version;
            await setParam(page, 'fxaa', 'subpix', ((i * 37) % 100) / 100);
            await waitPreview(page, 'preview-tonemap-color', before, 120000);
            if (i % 10 === 0) {
                await waitIdle(page);
                rss.push({ edits: i, kib: rssKiB(server.pid) });
                console.log(`  after ${i} edits: VmRSS ${(rss.at(-1).kib / 1024).toFixed(1)} MiB`);
            }
        }
        results.rss = rss;
        }

        if (!skip.includes('museum')) {
            console.log('museum.json (first opening bakes or loads the lightmaps)');
            const t0 = performance.now();
            await openGraph(page, server.url, 'graphs/museum.json', { timeout: 1800000 });
            results.museum_open_ms = Math.round(performance.now() - t0);
            console.log(`  opened and every thumbnail rendered after ${results.museum_open_ms} ms`);
            // Candidates for the README's screenshot (docs/editor-museum.png), while the Museum is open.
            await selectNode(page, 'grain');
            await page.screenshot({ path: path.join(out, 'museum-fit.png') });
            for (const [i, [at, steps]] of [['lens', 3], ['lens', 5], ['lighting', 4]].entries()) {
                await page.locator('.react-flow__controls-fitview').click().catch(() => {});
                await page.waitForTimeout(500);
                await zoomAt(page, at, steps);
                await page.screenshot({ path: path.join(out, `museum-zoom${i}.png`) });
            }
            await page.locator('.react-flow__controls-fitview').click().catch(() => {});
            await page.waitForTimeout(500);
            const m = await previewInfo(page, 'preview-grain-color');
            const mn = Math.max(2, Math.min(n, 3));
            results.museum = {
                preview: `${m.width}x${m.height}`,
                ao_intensity_to_final: stats(await timeEdits(page, 'ao', 'intensity', [0.3, 0.7, 0.5].slice(0, mn), 'preview-grain-color')),
                grain_strength_to_final: stats(await timeEdits(page, 'grain', 'strength', [0.02, 0.05, 0.01].slice(0, mn), 'preview-grain-color')),
            };
            results.museum_rss_kib = rssKiB(server.pid);
            const museumEdits = Number(opts['museum-edits']);
            if (museumEdits > 0) {
                console.log(`server VmRSS over ${museumEdits} edits of the museum's grain.strength`);
                const rss = [{ edits: 0, kib: rssKiB(server.pid) }];
                await selectNode(page, 'grain');
                for (let i = 1; i <= museumEdits; ++i) {
                    const before = (await previewInfo(page, 'preview-grain-color')).version;
                    await setParam(page, 'grain', 'strength', 0.01 + ((i * 37) % 100) / 2000);
                    await waitPreview(page, 'preview-grain-color', before, 600000);
                    if (i % 10 === 0) {
                        await waitIdle(page, 600000);
                        rss.push({ edits: i, kib: rssKiB(server.pid) });
                        console.log(`  after ${i} edits: VmRSS ${(rss.at(-1).kib / 1024).toFixed(1)} MiB`);
                    }
                }
                results.museum_rss = rss;
            }
        }
    } finally {
        await browser.close().catch(() => {});
        await server.stop();
        fs.rmSync(dir, { recursive: true, force: true });
        fs.writeFileSync(path.join(out, 'measurements.json'), JSON.stringify(results, null, 2) + '\n');
        console.log(`written ${path.join(out, 'measurements.json')}`);
    }
}

main().catch(e => {
    console.error(`measure: ${e instanceof Failure ? e.message : e.stack || e}`);
    process.exitCode = 1;
});
