#!/usr/bin/env node
// The graph editor in a real browser: headless Chromium from Debian (/usr/bin/chromium) driven by playwright-core
// from editor/node_modules, against `vitrine serve` on a loopback port it picks (--port 0) over a temporary copy of
// graphs/ and data/. The scenarios of issue 13, through the data-testids of editor/TESTING.md. Each scenario runs in
// a fresh page and leaves a screenshot (NAME.png, or NAME-FAIL.png) in --out; the server's log is server.log there.
//
// usage: node tests/editor/run.mjs --vitrine build/vitrine [--source .] [--out build/editor-test]
//                                  [--only name,name] [--keep]
// Exit status 0 when every scenario passed; 1 with "FAIL scenario: why" lines otherwise.
import fs from 'node:fs';
import path from 'node:path';
import { fileURLToPath } from 'node:url';
import {
    Failure, checkPrerequisites, connect, deleteNode, edgeCount, fail, jsonDiff, launchBrowser, makeServedDir,
    moveNodeToFreeSpace, nodeNames, openGraph, parseArgs, pixelDifference, poll, previewInfo, readJson, resetGraphs, selectNode,
    setParam, startServer, thumbnailPixels, tid, waitIdle, waitPreview, waitVisible,
} from './lib.mjs';

const here = path.dirname(fileURLToPath(import.meta.url));
const opts = parseArgs(process.argv.slice(2), { source: path.resolve(here, '..', '..'), out: 'editor-test' });
const source = path.resolve(opts.source);
const out = path.resolve(opts.out);
const vitrine = opts.vitrine && path.resolve(opts.vitrine);
const ZONEPLATE = 'graphs/fxaa_zoneplate.json';
const NO_FXAA = 'graphs/variants/no_fxaa.json';

let dir, server;
const served = rel => path.join(dir, rel);
const originalOf = rel => path.join(source, rel);

// Save-as (variant or whole graph) to REL through the dialog of editor/TESTING.md; waits for the file to appear.
async function saveAs(page, button, rel) {
    await page.locator(tid(button)).click();
    await waitVisible(page, 'save-as-path', `${button}: the path entry`, 10000);
    await page.locator(tid('save-as-path')).fill(rel);
    await page.locator(tid('save-as-confirm')).click();
    await poll(() => fs.existsSync(served(rel)), `${button} to ${rel}: no file written`, 30000);
    await waitIdle(page, 60000);
    return readJson(served(rel));
}


async function expectNodes(page, expected, what) {
    await poll(async () => {
        const names = new Set(await nodeNames(page));
        return expected.every(n => names.has(n));
    }, async () => `${what}: expected nodes ${expected.join(', ')} on the canvas, found ${(await nodeNames(page)).join(', ')}`,
    30000);
}

const scenarios = [
    {
        name: 'open',
        what: 'opening graphs/fxaa_zoneplate.json draws its nodes, ports (with kinds), wires and thumbnails',
        async run(page) {
            await openGraph(page, server.url, ZONEPLATE);
            await expectNodes(page, ['pattern', 'fxaa', 'tonemap', 'output-final'], 'open');
            for (const [id, kind] of [['out-pattern-color', 'texture'], ['in-fxaa-color', 'texture'],
                                      ['out-fxaa-color', 'texture'], ['in-tonemap-color', 'texture'],
                                      ['in-tonemap-camera_state', 'buffer'], ['in-output-final-value', null]]) {
                const h = page.locator(tid(id));
                if (!await h.count()) fail(`open: no handle [data-testid="${id}"]`);
                const k = await h.first().getAttribute('data-kind');
                if (kind && k !== kind) fail(`open: handle ${id} has data-kind="${k}", expected "${kind}"`);
            }
            const edges = await edgeCount(page);
            if (edges !== 3) fail(`open: ${edges} wires drawn, expected 3 (pattern->fxaa, fxaa->tonemap, tonemap->final)`);
            for (const id of ['preview-pattern-color', 'preview-fxaa-color', 'preview-tonemap-color']) {
                const info = await waitPreview(page, id);
                if (info.width < 16 || info.height < 9) fail(`open: thumbnail ${id} is ${info.width}x${info.height}`);
            }
            if (await page.locator(tid('dirty')).count()) fail('open: marked dirty (unsaved edits) right after opening');
        },
    },
    {
        name: 'roundtrip',
        what: 'open -> save without edits leaves graphs and variants JSON-identical (byte-identical noted)',
        async run(page, log) {
            // Renders are not needed here: refused, so that the Museum's previews do not queue up on the server.
            await page.route('**/api/render', route => route.abort());
            await page.route('**/api/compare', route => route.abort());
            for (const rel of [ZONEPLATE, NO_FXAA, 'graphs/museum.json']) {
                await openGraph(page, server.url, rel, { idle: false });
                const before = fs.statSync(served(rel)).mtimeMs;
                const button = page.locator(tid('save'));
                if (await button.isDisabled()) fail(`roundtrip: save is disabled after opening ${rel} (nothing to test)`);
                await button.click();
                await poll(() => fs.statSync(served(rel)).mtimeMs !== before,
                           `roundtrip: saving ${rel}: the file was not written`, 30000);
                const written = fs.readFileSync(served(rel));
                const original = fs.readFileSync(originalOf(rel));
                const d = jsonDiff(JSON.parse(written), JSON.parse(original));
                if (d) fail(`roundtrip: saving ${rel} without edits changed it at ${d}`);
                log(`${rel}: JSON-identical, ${written.equals(original) ? 'byte-identical' : 'not byte-identical'}`);
            }
        },
    },
    {
        name: 'subpix',
        what: "changing FXAA's subpix re-renders the thumbnails downstream (pixel check), not upstream",
        async run(page, log) {
            await openGraph(page, server.url, ZONEPLATE);
            const ids = ['preview-pattern-color', 'preview-fxaa-color', 'preview-tonemap-color'];
            const before = {};
            for (const id of ids) {
                before[id] = await waitPreview(page, id);
                before[id].pixels = await thumbnailPixels(page, id);
            }
            await selectNode(page, 'fxaa');
            const t0 = Date.now();
            await setParam(page, 'fxaa', 'subpix', 0);
            for (const id of ['preview-fxaa-color', 'preview-tonemap-color']) {
                await waitPreview(page, id, before[id].version);
                const diff = pixelDifference(before[id].pixels, await thumbnailPixels(page, id));
                log(`${id}: updated after ${Date.now() - t0} ms; mean |diff| ${diff.mean.toFixed(2)}/255, ` +
                    `${(100 * diff.changed).toFixed(1)}% of pixels changed by more than 8/255`);
                // At 256x144 the CLI measures PSNR 22 dB between subpix 0.75 and 0 on this plate.
                if (!(diff.mean > 0.5 && diff.changed > 0.01))
                    fail(`subpix: thumbnail ${id} did not change visibly (mean |diff| ${diff.mean.toFixed(3)}/255, ` +
                         `${(100 * diff.changed).toFixed(2)}% of pixels)`);
            }
            await waitIdle(page);
            const pattern = await previewInfo(page, 'preview-pattern-color');
            const diff = pixelDifference(before['preview-pattern-color'].pixels,
                                         await thumbnailPixels(page, 'preview-pattern-color'));
            if (diff.mean > 0.01) fail(`subpix: the pattern's thumbnail (upstream of fxaa) changed (mean ${diff.mean})`);
            log(`preview-pattern-color: version ${before['preview-pattern-color'].version} -> ${pattern.version}`);
            if (!await page.locator(tid('dirty')).count()) fail('subpix: an edit does not mark the graph dirty');
            if (!fs.readFileSync(served(ZONEPLATE)).equals(fs.readFileSync(originalOf(ZONEPLATE))))
                fail('subpix: the file changed on disk without a save');
        },
    },
    {
        name: 'variant',
        what: 'delete FXAA, wire pattern -> tonemap, save as a variant: equals graphs/variants/no_fxaa.json',
        async run(page, log) {
            await openGraph(page, server.url, ZONEPLATE);
            await deleteNode(page, 'fxaa');
            await poll(async () => (await edgeCount(page)) === 1,
                       async () => `variant: after deleting fxaa ${await edgeCount(page)} wires, expected 1 (tonemap->final)`, 10000);
            await connect(page, 'out-pattern-color', 'in-tonemap-color');
            await poll(async () => (await edgeCount(page)) === 2,
                       async () => `variant: after wiring pattern.color -> tonemap.color ${await edgeCount(page)} wires, expected 2`,
                       10000);
            await waitPreview(page, 'preview-tonemap-color');
            const rel = 'graphs/variants/edited_no_fxaa.json';
            const written = await saveAs(page, 'save-as-variant', rel);
            const expected = readJson(originalOf(NO_FXAA));
            // The description is the user's text: the editor may leave it out or write its own.
            delete expected.description;
            delete written.description;
            const d = jsonDiff(written, expected);
            if (d) fail(`variant: ${rel} differs from ${NO_FXAA} at ${d}:\n${JSON.stringify(written, null, 1)}`);
            log(`${rel}: ${JSON.stringify(written)}`);
            if (!fs.readFileSync(served(ZONEPLATE)).equals(fs.readFileSync(originalOf(ZONEPLATE))))
                fail('variant: saving a variant changed the base graph');
        },
    },
    {
        name: 'palette',
        what: 'add post.grain from the palette (searched), wire it, refuse a texture into a buffer port, save as',
        async run(page, log) {
            await openGraph(page, server.url, ZONEPLATE);
            await waitVisible(page, 'palette', 'palette');
            await page.locator(tid('palette-search')).fill('grain');
            const item = page.locator(tid('palette-item-post.grain'));
            await item.waitFor({ state: 'visible', timeout: 10000 }).catch(() => fail('palette: searching "grain" shows no palette-item-post.grain'));
            if (await page.locator(tid('palette-item-aa.fxaa')).isVisible().catch(() => false))
                fail('palette: searching "grain" still shows aa.fxaa');
            await item.click();
            await expectNodes(page, ['grain'], 'palette');
            await poll(async () => (await page.locator(tid('inspector-name')).textContent().catch(() => '')).trim() === 'grain',
                       'palette: the new node grain is not selected', 10000);
            // Out of the way of the other nodes, as a user would, wherever the palette put it.
            await moveNodeToFreeSpace(page, 'grain');
            const edges0 = await edgeCount(page);
            await connect(page, 'out-pattern-color', 'in-grain-camera_state');
            await page.waitForTimeout(300);
            if ((await edgeCount(page)) !== edges0) fail('palette: a texture was wired into the buffer port grain.camera_state');
            const status = (await page.locator(tid('status')).textContent().catch(() => '')) || '';
            if (!/kind|texture|buffer/i.test(status))
                fail(`palette: refusing a texture -> buffer wire: status says "${status.trim()}", not why`);
            log(`refused wire, status: "${status.trim()}"`);
            await connect(page, 'out-tonemap-color', 'in-grain-color');
            await connect(page, 'out-grain-color', 'in-output-final-value');
            await waitPreview(page, 'preview-grain-color');
            const rel = 'graphs/with_grain.json';
            const written = await saveAs(page, 'save-as', rel);
            const grain = written.nodes?.grain;
            if (grain?.type !== 'post.grain') fail(`palette: ${rel} has no post.grain node "grain": ${JSON.stringify(written.nodes)}`);
            if (grain.in?.color !== 'tonemap.color') fail(`palette: grain.in.color is ${JSON.stringify(grain.in)}, expected tonemap.color`);
            if (grain.in?.camera_state) fail('palette: the refused wire was saved');
            if (written.outputs?.final !== 'grain.color') fail(`palette: outputs.final is ${JSON.stringify(written.outputs)}, expected grain.color`);
            if (written.nodes?.tonemap?.in?.color !== 'fxaa.color') fail('palette: tonemap lost its input');
        },
    },
    {
        name: 'invalid_param',
        what: 'an out-of-range or mistyped param value shows an error on that param, and clears when fixed',
        async run(page, log) {
            await openGraph(page, server.url, ZONEPLATE);
            await selectNode(page, 'fxaa');
            for (const [key, bad] of [['subpix', 5], ['search_steps', 2.5]]) {
                await setParam(page, 'fxaa', key, bad);
                const err = page.locator(tid(`param-error-fxaa-${key}`));
                await err.first().waitFor({ state: 'visible', timeout: 30000 })
                    .catch(() => fail(`invalid_param: fxaa.${key} = ${bad} shows no param-error-fxaa-${key}`));
                const text = (await err.first().textContent()).trim();
                if (!text) fail(`invalid_param: param-error-fxaa-${key} is empty`);
                log(`fxaa.${key} = ${bad}: "${text}"`);
            }
            if (!await page.locator(tid('param-error-fxaa-subpix')).isVisible()) fail('invalid_param: the subpix error went away by itself');
            await setParam(page, 'fxaa', 'subpix', 0.5);
            await setParam(page, 'fxaa', 'search_steps', 8);
            await poll(async () => (await page.locator(tid('param-error-fxaa-subpix')).count()) === 0 &&
                                   (await page.locator(tid('param-error-fxaa-search_steps')).count()) === 0,
                       'invalid_param: the errors stay after valid values were entered', 30000);
        },
    },
    {
        name: 'variant_open',
        what: 'opening graphs/variants/no_fxaa.json shows the merged graph (no fxaa, pattern -> tonemap)',
        async run(page) {
            await openGraph(page, server.url, NO_FXAA);
            await expectNodes(page, ['pattern', 'tonemap', 'output-final'], 'variant_open');
            if (await page.locator(tid('node-fxaa')).count()) fail('variant_open: the deleted node fxaa is drawn');
            const edges = await edgeCount(page);
            if (edges !== 2) fail(`variant_open: ${edges} wires, expected 2 (pattern->tonemap, tonemap->final)`);
            await waitPreview(page, 'preview-tonemap-color');
            await selectNode(page, 'tonemap');
            const op = await page.locator(tid('param-tonemap-operator')).inputValue();
            if (op !== 'linear') fail(`variant_open: tonemap.operator shows "${op}", the base graph's is "linear"`);
        },
    },
    {
        name: 'viewer',
        what: 'a click on a thumbnail opens the large viewer; its channel control re-renders (alpha: all white)',
        async run(page, log) {
            await openGraph(page, server.url, ZONEPLATE);
            await waitPreview(page, 'preview-tonemap-color');
            await page.locator(tid('preview-tonemap-color')).click();
            await waitVisible(page, 'viewer', 'viewer: clicking the tonemap thumbnail', 10000);
            const ready = async () => page.locator(tid('viewer-image')).evaluate(e => e.dataset.state !== 'loading' &&
                                                                                        e.complete && e.naturalWidth > 0);
            await poll(ready, 'viewer: viewer-image shows no image', 120000);
            const rgb = await thumbnailPixels(page, 'viewer-image');
            await page.locator(tid('viewer-channel')).selectOption('a');
            await poll(async () => (await ready()) && pixelDifference(rgb, await thumbnailPixels(page, 'viewer-image')).mean > 20,
                       'viewer: choosing channel "a" did not change the image (an opaque image\'s alpha is white)', 120000);
            const a = await thumbnailPixels(page, 'viewer-image');
            let dark = 0;
            for (let i = 0; i < a.data.length; i += 4) if (a.data[i] < 250) ++dark;
            log(`viewer ${a.width}x${a.height}; channel a: ${dark} of ${a.data.length / 4} pixels below 250`);
            if (dark > a.data.length / 400) fail(`viewer: the alpha channel of the tone-mapped plate is not white (${dark} pixels)`);
            await page.locator(tid('viewer-close')).click();
            await poll(async () => !(await page.locator(tid('viewer')).isVisible().catch(() => false)), 'viewer: viewer-close did not close it', 10000);
        },
    },
    {
        name: 'prev_links',
        what: "museum.json's @prev history links are drawn dashed and labelled @prev",
        async run(page, log) {
            await page.route('**/api/render', route => route.abort());
            await openGraph(page, server.url, 'graphs/museum.json', { idle: false });
            const expected = (fs.readFileSync(originalOf('graphs/museum.json'), 'utf8').match(/"[A-Za-z_0-9]+\.[A-Za-z_0-9]+@prev"/g) || []).length;
            const drawn = await poll(async () => page.locator('.vitrine-edge-prev').count(), 'prev_links: no .vitrine-edge-prev wire', 30000);
            const labels = await page.locator('.react-flow__edge-text, .react-flow__edgelabel-renderer').allTextContents();
            const labelled = labels.join(' ').split('@prev').length - 1;
            log(`${drawn} @prev wires drawn (${expected} "…@prev" references in the file), ${labelled} labels`);
            if (drawn !== expected) fail(`prev_links: ${drawn} @prev wires drawn, the file has ${expected}`);
            if (labelled < 1) fail('prev_links: no @prev label on the history wires');
            const dashed = await page.locator('.vitrine-edge-prev path, path.vitrine-edge-prev').first()
                .evaluate(e => getComputedStyle(e).strokeDasharray).catch(() => 'none');
            if (!dashed || dashed === 'none') fail(`prev_links: the @prev wire is not dashed (stroke-dasharray ${dashed})`);
        },
    },
    {
        name: 'ab',
        what: 'A/B of fxaa_zoneplate vs no_fxaa shows both images, the FLIP map and a FLIP value; A vs A gives 0',
        async run(page, log) {
            await openGraph(page, server.url, ZONEPLATE);
            await page.locator(tid('ab-open')).click();
            await waitVisible(page, 'ab', 'ab: the A/B panel', 10000);
            const pick = async (id, rel) => {
                const sel = page.locator(tid(id));
                const values = await sel.locator('option').evaluateAll(os => os.map(o => o.value));
                const v = values.find(x => x === rel) ?? values.find(x => x.endsWith(rel));
                if (!v) fail(`ab: ${id} offers no ${rel} (options: ${values.join(', ')})`);
                await sel.selectOption(v);
            };
            const run = async (a, b) => {
                await pick('ab-a', a);
                await pick('ab-b', b);
                const old = await page.locator(tid('ab-metric-flip')).textContent().catch(() => null);
                const oldSrc = await page.locator(tid('ab-image-b')).getAttribute('src').catch(() => null);
                await page.locator(tid('ab-run')).click();
                await poll(async () => {
                    const src = await page.locator(tid('ab-image-b')).getAttribute('src').catch(() => null);
                    const t = await page.locator(tid('ab-metric-flip')).textContent().catch(() => null);
                    return src && t && (src !== oldSrc || t !== old) && await page.locator(tid('app')).getAttribute('data-state') === 'idle';
                }, `ab: no result for ${a} vs ${b}`, 180000);
                for (const id of ['ab-image-a', 'ab-image-b', 'ab-flip']) {
                    const ok = await page.locator(tid(id)).first().evaluate(e => e.complete && e.naturalWidth > 0).catch(() => false);
                    if (!ok) fail(`ab: ${id} shows no image after comparing ${a} with ${b}`);
                }
                const text = (await page.locator(tid('ab-metric-flip')).textContent()).trim();
                const flip = Number(text.match(/-?\d+(\.\d+)?(e-?\d+)?/i)?.[0]);
                if (!Number.isFinite(flip)) fail(`ab: ab-metric-flip shows "${text}", not a number`);
                return flip;
            };
            const flip = await run(ZONEPLATE, NO_FXAA);
            log(`FLIP mean fxaa_zoneplate vs no_fxaa: ${flip}`);
            // vitrine compare of the two at 640x360 gives a FLIP mean of about 0.04; any size gives well above 0.005.
            if (!(flip > 0.005 && flip < 0.5)) fail(`ab: FLIP ${flip} for fxaa vs no fxaa, expected 0.005..0.5`);
            const slider = page.locator(tid('ab-slider'));
            if (!await slider.count() || await slider.getAttribute('type') !== 'range') fail('ab: no ab-slider range input');
            await slider.fill('25');
            await page.screenshot({ path: path.join(out, 'ab-split.png') });
            const same = await run(ZONEPLATE, ZONEPLATE);
            log(`FLIP mean fxaa_zoneplate vs itself: ${same}`);
            if (same !== 0) fail(`ab: FLIP of a graph against itself is ${same}, expected 0`);
        },
    },
];


// Issue #27's editor items: unsaved edits are guarded and kept, params an input replaces are shown so, the view fits.
scenarios.push(
    {
        name: 'unsaved',
        what: 'an edit marks the graph dirty; reload asks first (beforeunload); reopening offers the autosaved edits ' +
              '(restore brings them back, discard drops them); the file is never written; the favicon is served',
        async run(page, log) {
            const missing = [];
            page.on('response', r => { if (r.status() === 404) missing.push(r.url()); });
            await openGraph(page, server.url, ZONEPLATE);
            if (await page.locator(tid('autosave-offer')).count()) fail('unsaved: an autosave offered on a first open');
            await selectNode(page, 'fxaa');
            await setParam(page, 'fxaa', 'subpix', 0.125);
            await waitVisible(page, 'dirty', 'unsaved: the dirty mark after an edit', 10000);
            await page.waitForTimeout(1000); // past the autosave's 300 ms debounce
            const dialogs = page.vitrineDialogs;
            dialogs.length = 0;
            await page.reload();
            log(`dialogs on reload with unsaved edits: ${JSON.stringify(dialogs)}`);
            if (!dialogs.includes('beforeunload')) fail(`unsaved: reload with unsaved edits did not ask (dialogs ${JSON.stringify(dialogs)})`);
            await waitVisible(page, 'autosave-offer', 'unsaved: reopening offers the autosaved edits', 60000);
            if (await page.locator(tid('dirty')).count()) fail('unsaved: dirty before the autosave was restored');
            await page.locator(tid('autosave-restore')).click();
            await waitVisible(page, 'dirty', 'unsaved: restored edits are unsaved edits', 10000);
            await selectNode(page, 'fxaa');
            const restored = await page.locator(tid('param-fxaa-subpix')).inputValue();
            if (Number(restored) !== 0.125) fail(`unsaved: the restored subpix is ${restored}, expected 0.125`);
            log(`restored subpix ${restored}`);
            // Discard: the offer is gone for good, the document is the file's.
            await page.waitForTimeout(1000);
            dialogs.length = 0;
            await page.reload();
            await waitVisible(page, 'autosave-offer', 'unsaved: the offer again after a second reload', 60000);
            await page.locator(tid('autosave-discard')).click();
            if (await page.locator(tid('dirty')).count()) fail('unsaved: dirty after discarding');
            dialogs.length = 0;
            await page.reload();
            await waitVisible(page, 'app', 'unsaved: the page after discarding', 30000);
            await waitIdle(page);
            if (dialogs.includes('beforeunload')) fail('unsaved: reload without unsaved edits asked');
            if (await page.locator(tid('autosave-offer')).count()) fail('unsaved: the offer came back after discarding');
            if (!fs.readFileSync(served(ZONEPLATE)).equals(fs.readFileSync(originalOf(ZONEPLATE))))
                fail('unsaved: the file changed on disk without a save');
            const icon = await page.evaluate(async () => {
                const link = document.querySelector('link[rel="icon"]');
                return link ? (await fetch(link.href)).status : 0;
            });
            if (icon !== 200) fail(`unsaved: the favicon is not served (${icon})`);
            if (missing.length) fail(`unsaved: 404 answers: ${missing.join(', ')}`);
        },
    },
    {
        name: 'set_by_input',
        what: "camera_checker: tonemap's exposure and grain's iso (replaced by the connected camera_state) are shown " +
              'disabled, "set by input camera_state"; on fxaa_zoneplate (no camera) exposure is editable',
        async run(page, log) {
            await openGraph(page, server.url, 'graphs/camera_checker.json', { idle: false });
            for (const [node, key] of [['tonemap', 'exposure'], ['grain', 'iso']]) {
                await selectNode(page, node);
                const note = page.locator(tid(`param-setby-${node}-${key}`));
                await note.waitFor({ state: 'visible', timeout: 10000 })
                    .catch(() => fail(`set_by_input: ${node}.${key} not marked as set by an input`));
                const text = await note.textContent();
                if (!text.includes('set by input camera_state')) fail(`set_by_input: ${node}.${key} says "${text}"`);
                if (!await page.locator(tid(`param-${node}-${key}`)).isDisabled())
                    fail(`set_by_input: ${node}.${key}'s entry is not disabled`);
                log(`${node}.${key}: "${text.trim()}", disabled`);
                if (node === 'tonemap' && await page.locator(tid('param-tonemap-operator')).isDisabled())
                    fail('set_by_input: tonemap.operator disabled too');
            }
            await openGraph(page, server.url, ZONEPLATE, { idle: false });
            await selectNode(page, 'tonemap');
            if (await page.locator(tid('param-setby-tonemap-exposure')).count())
                fail('set_by_input: exposure marked although camera_state is not connected');
            if (await page.locator(tid('param-tonemap-exposure')).isDisabled()) fail('set_by_input: exposure disabled without a camera');
        },
    },
    {
        name: 'saveas_cache',
        what: 'save as (same folder) and save as variant (another folder) keep every thumbnail: none is rendered again',
        async run(page, log) {
            await openGraph(page, server.url, ZONEPLATE);
            await selectNode(page, 'fxaa');
            await setParam(page, 'fxaa', 'subpix', 0.25);
            await waitIdle(page);
            const versions = async () => page.$$eval('img[data-testid^="preview-"]',
                                                     els => Object.fromEntries(els.map(e => [e.dataset.testid, e.dataset.version])));
            const before = await versions();
            if (Object.keys(before).length < 3) fail(`saveas_cache: only ${Object.keys(before).length} thumbnails`);
            await saveAs(page, 'save-as', 'graphs/zoneplate_copy.json');
            await page.waitForTimeout(1000);
            await waitIdle(page);
            const afterCopy = await versions();
            await saveAs(page, 'save-as-variant', 'graphs/variants/subpix_025.json');
            await page.waitForTimeout(1000);
            await waitIdle(page);
            const afterVariant = await versions();
            log(`thumbnail versions: ${JSON.stringify(before)} -> ${JSON.stringify(afterCopy)} -> ${JSON.stringify(afterVariant)}`);
            if (JSON.stringify(afterCopy) !== JSON.stringify(before)) fail('saveas_cache: save as re-rendered thumbnails');
            if (JSON.stringify(afterVariant) !== JSON.stringify(before))
                fail('saveas_cache: save as variant re-rendered thumbnails');
            const current = (await page.locator(tid('current-file')).textContent()) || '';
            if (!current.includes('graphs/variants/subpix_025.json')) fail(`saveas_cache: current file is "${current}"`);
        },
    },
    {
        name: 'fit',
        what: 'the museum graph (51 nodes and outputs, laid out automatically) opens fitted: every node inside the canvas',
        async run(page, log) {
            // The museum's layout, without its minutes of lightmap baking on lavapipe: a param its scene node does not
            // have fails validation, so that every render is refused at once (the server would otherwise bake on after
            // the test, past the harness's shutdown wait).
            const doc = readJson(originalOf('graphs/museum.json'));
            doc.nodes.scene.params.not_a_param_fit_test = 1;
            const rel = 'graphs/museum_layout.json';
            fs.writeFileSync(served(rel), JSON.stringify(doc, null, 2));
            await openGraph(page, server.url, rel, { idle: false });
            const expected = Object.keys(doc.nodes).length + Object.keys(doc.outputs).length;
            const names = await poll(async () => {
                const n = await nodeNames(page);
                return n.length >= expected ? n : null;
            }, async () => `fit: ${(await nodeNames(page)).length} of ${expected} nodes drawn`, 60000);
            await page.waitForTimeout(1500);
            const canvas = await page.locator('.canvas').boundingBox();
            const outside = [];
            for (const name of names) {
                const b = await page.locator(tid(`node-${name}`)).boundingBox();
                if (!b || b.x < canvas.x - 1 || b.y < canvas.y - 1 || b.x + b.width > canvas.x + canvas.width + 1 ||
                    b.y + b.height > canvas.y + canvas.height + 1) outside.push(name);
            }
            log(`${names.length} nodes, ${outside.length} outside the canvas`);
            if (outside.length) fail(`fit: ${outside.length} of ${names.length} nodes outside the canvas: ${outside.slice(0, 8).join(', ')}`);
            await waitIdle(page);
        },
    },
);

async function main() {
    checkPrerequisites(source, vitrine);
    fs.mkdirSync(out, { recursive: true });
    for (const f of fs.readdirSync(out)) if (f.endsWith('.png')) fs.rmSync(path.join(out, f));
    const only = typeof opts.only === 'string' ? opts.only.split(',') : null;
    const unknown = (only || []).filter(n => !scenarios.some(s => s.name === n));
    if (unknown.length) fail(`--only: no scenario ${unknown.join(', ')} (have ${scenarios.map(s => s.name).join(', ')})`);

    dir = makeServedDir(source);
    console.log(`editor tests: serving a copy of graphs/ and data/ in ${dir}`);
    server = await startServer({ vitrine, dir, editorDist: path.join(source, 'editor', 'dist'),
                                 logFile: path.join(out, 'server.log'), extraArgs: ['--validate'] });
    console.log(`editor tests: vitrine serve at ${server.url} (pid ${server.pid}); Chromium ${path.basename(process.env.VITRINE_CHROMIUM || '/usr/bin/chromium')}`);
    const browser = await launchBrowser(source);
    const failed = [];
    let passed = 0;
    try {
        for (const sc of scenarios) {
            if (only && !only.includes(sc.name)) continue;
            resetGraphs(source, dir);
            const context = await browser.newContext({ viewport: { width: 1600, height: 1000 } });
            const page = await context.newPage();
            page.setDefaultTimeout(30000);
            // beforeunload prompts (the editor asks before leaving unsaved edits) are accepted, so that navigation
            // goes on; their types are kept for the scenarios that check them.
            page.vitrineDialogs = [];
            page.on('dialog', d => {
                page.vitrineDialogs.push(d.type());
                void (d.type() === 'beforeunload' ? d.accept() : d.dismiss());
            });
            const pageErrors = [];
            const consoleErrors = [];
            page.on('pageerror', e => pageErrors.push(e.message));
            page.on('console', m => { if (m.type() === 'error') consoleErrors.push(m.text()); });
            const badResponses = [];
            page.on('response', r => { if (r.status() >= 400) badResponses.push(`${r.status()} ${r.request().method()} ${r.url().replace(server.url, '/')}`); });
            const t0 = Date.now();
            console.log(`--- ${sc.name}: ${sc.what}`);
            const log = msg => console.log(`    ${msg}`);
            try {
                await sc.run(page, log);
                if (pageErrors.length) fail(`uncaught errors in the page: ${pageErrors.join(' | ')}`);
                if (!server.alive()) fail('the server died');
                await page.screenshot({ path: path.join(out, `${sc.name}.png`) });
                ++passed;
                console.log(`PASS ${sc.name} (${((Date.now() - t0) / 1000).toFixed(1)} s)`);
            } catch (e) {
                const why = e instanceof Failure ? e.message : `${e.stack || e}`;
                failed.push(sc.name);
                console.log(`FAIL ${sc.name} (${((Date.now() - t0) / 1000).toFixed(1)} s): ${why}`);
                if (consoleErrors.length) console.log(`    browser console errors: ${consoleErrors.slice(-5).join(' | ')}`);
                if (badResponses.length) console.log(`    failed requests: ${badResponses.slice(-8).join(' | ')}`);
                if (pageErrors.length) console.log(`    uncaught page errors: ${pageErrors.slice(-5).join(' | ')}`);
                await page.screenshot({ path: path.join(out, `${sc.name}-FAIL.png`) }).catch(() => {});
            }
            await context.close();
        }
    } finally {
        await browser.close().catch(() => {});
        const stopped = await server.stop();
        if (stopped.code !== 0) {
            failed.push('server-exit');
            console.log(`FAIL server-exit: vitrine serve ended with ${JSON.stringify(stopped)} on SIGTERM (log: ${path.join(out, 'server.log')})`);
        }
    }
    if (failed.length && opts.keep !== true) console.log(`(served directory kept for inspection: ${dir})`);
    else if (!opts.keep) fs.rmSync(dir, { recursive: true, force: true });
    console.log(`editor tests: ${passed} passed, ${failed.length} failed${failed.length ? ': ' + failed.join(', ') : ''}; ` +
                `screenshots in ${out}`);
    process.exitCode = failed.length ? 1 : 0;
}

main().catch(e => {
    console.error(`editor tests: ${e instanceof Failure ? e.message : e.stack || e}`);
    process.exitCode = 1;
    // Children (the server) are killed on exit.
});
