// Renders glTF files with the Khronos glTF Sample Viewer's engine (npm @khronosgroup/gltf-viewer, installed by
// tools/install-deps.sh from tools/gltf-viewer/package-lock.json) in Debian's headless Chromium on SwiftShader (WebGL 2
// in software), driven by playwright-core from editor/node_modules with executablePath: no browser is downloaded.
// Every request of the page is answered from the checkout (page.route); nothing goes to the network.
//
// Usage: node render.mjs SOURCE_DIR JOBS.json
//   JOBS.json: {"width": W, "height": H, "cases": [{"gltf": PATH, "out": PNG, "exposure": E, "iblIntensity": I,
//               "lightScale": S, "environmentRotation": DEG}, ...]}
// Prints one line per case with its time; exits 1 with the page's console on any failure.
import fs from 'node:fs';
import { createRequire } from 'node:module';
import path from 'node:path';
import zlib from 'node:zlib';

const [sourceArg, jobsFile] = process.argv.slice(2);
const source = sourceArg && path.resolve(sourceArg);
if (!sourceArg || !jobsFile) {
    console.error('usage: node render.mjs SOURCE_DIR JOBS.json');
    process.exit(2);
}
const jobs = JSON.parse(fs.readFileSync(jobsFile, 'utf8'));
const dist = path.join(source, 'tools', 'gltf-viewer', 'node_modules', '@khronosgroup', 'gltf-viewer', 'dist');
const chromium = process.env.VITRINE_CHROMIUM || '/usr/bin/chromium';
const problems = [];
if (!fs.existsSync(path.join(dist, 'gltf-viewer.module.js')))
    problems.push(`${dist}/gltf-viewer.module.js is missing (run tools/install-deps.sh: npm ci in tools/gltf-viewer/)`);
if (!fs.existsSync(path.join(source, 'editor', 'node_modules', 'playwright-core')))
    problems.push('editor/node_modules/playwright-core is missing (run tools/install-deps.sh: npm ci in editor/)');
if (!fs.existsSync(chromium))
    problems.push(`no Chromium at ${chromium} (tools/install-deps.sh installs Debian's chromium)`);
if (problems.length) {
    console.error('render.mjs: ' + problems.join('\n  '));
    process.exit(1);
}

// A 2x2 RGBA PNG, all texels (255, 255, 255, 255): the sheen albedo-scaling LUT the engine loads with every
// environment but does not ship; it only scales KHR_materials_sheen, which none of the test files uses.
function whitePng() {
    const crcTable = Array.from({ length: 256 }, (_, n) => {
        let c = n;
        for (let k = 0; k < 8; ++k) c = c & 1 ? 0xedb88320 ^ (c >>> 1) : c >>> 1;
        return c >>> 0;
    });
    const crc = buf => {
        let c = 0xffffffff;
        for (const b of buf) c = crcTable[(c ^ b) & 0xff] ^ (c >>> 8);
        return (c ^ 0xffffffff) >>> 0;
    };
    const chunk = (type, data) => {
        const len = Buffer.alloc(4);
        len.writeUInt32BE(data.length);
        const td = Buffer.concat([Buffer.from(type, 'ascii'), data]);
        const c = Buffer.alloc(4);
        c.writeUInt32BE(crc(td));
        return Buffer.concat([len, td, c]);
    };
    const ihdr = Buffer.alloc(13);
    ihdr.writeUInt32BE(2, 0);
    ihdr.writeUInt32BE(2, 4);
    ihdr.set([8, 6, 0, 0, 0], 8);
    const row = Buffer.from([0, 255, 255, 255, 255, 255, 255, 255, 255]);
    return Buffer.concat([Buffer.from([0x89, 0x50, 0x4e, 0x47, 0x0d, 0x0a, 0x1a, 0x0a]), chunk('IHDR', ihdr),
                          chunk('IDAT', zlib.deflateSync(Buffer.concat([row, row]))), chunk('IEND', Buffer.alloc(0))]);
}

const origin = 'http://viewer.test';
const files = new Map([
    ['/page.html', path.join(source, 'tests', 'viewer', 'page.html')],
    ['/page.mjs', path.join(source, 'tests', 'viewer', 'page.mjs')],
    ['/env/studio.hdr', path.join(source, 'data', 'env', 'studio.hdr')],
    ['/viewer/gltf-viewer.module.js', path.join(dist, 'gltf-viewer.module.js')],
    ['/viewer/libs/libktx.js', path.join(dist, 'libs', 'libktx.js')],
    ['/viewer/libs/libktx.wasm', path.join(dist, 'libs', 'libktx.wasm')],
    ['/viewer/libs/mikktspace_bg.wasm', path.join(dist, 'libs', 'mikktspace_bg.wasm')],
]);
jobs.cases.forEach((c, i) => files.set(`/scenes/${i}/${path.basename(c.gltf)}`, path.resolve(c.gltf)));
// The engine prefilters the environment on the GPU with fixed sizes (iblSampler: 256^2 cube faces, 2048 Lambertian
// and 1024 GGX samples per texel, a 1024^2 GGX/Charlie LUT at 1024 samples per texel): about 3.5e9 texture samples,
// which SwiftShader on two shared cores did not finish in 5 minutes. The module is served with smaller constants
// (these four lines only, each checked to occur exactly once): 128^2 faces, 256 samples, a 128^2 LUT. Filtered
// importance sampling (each sample reads a mip level matched to its pdf) keeps 256 samples smooth on data/env/
// studio.hdr, whose finest feature is a cos^8 lobe, and the LUT is a smooth function of (NdotV, roughness).
const iblSizes = [
    ['this.textureSize = 256;', 'this.textureSize = 128;'],
    ['this.ggxSampleCount = 1024;', 'this.ggxSampleCount = 256;'],
    ['this.lambertianSampleCount = 2048;', 'this.lambertianSampleCount = 256;'],
    ['this.lutResolution = 1024;', 'this.lutResolution = 128;'],
];
function viewerModule() {
    let text = fs.readFileSync(path.join(dist, 'gltf-viewer.module.js'), 'utf8');
    for (const [from, to] of iblSizes) {
        const n = text.split(from).length - 1;
        if (n !== 1)
            throw new Error(`gltf-viewer.module.js: expected '${from}' once, found it ${n} times (another version?)`);
        text = text.replace(from, to);
    }
    return text;
}
const moduleText = viewerModule();
const types = { '.html': 'text/html', '.mjs': 'text/javascript', '.js': 'text/javascript', '.wasm': 'application/wasm',
                '.gltf': 'model/gltf+json', '.hdr': 'application/octet-stream', '.png': 'image/png' };

const require = createRequire(path.join(source, 'editor', 'package.json'));
const { chromium: launcher } = require('playwright-core');
// WebGL 2 on SwiftShader through ANGLE (Chromium's software GL; --enable-unsafe-swiftshader: newer Chromium only falls
// back to it when asked). VITRINE_VIEWER_CHROMIUM_FLAGS replaces these flags.
const defaultFlags = '--use-gl=angle --use-angle=swiftshader --enable-unsafe-swiftshader --ignore-gpu-blocklist';
const flags = (process.env.VITRINE_VIEWER_CHROMIUM_FLAGS || defaultFlags).split(/\s+/);
const browser = await launcher.launch({
    executablePath: chromium,
    headless: true,
    // Root has no user namespaces for the sandbox; the page is our own and never leaves http://viewer.test.
    args: ['--no-sandbox', '--disable-dev-shm-usage', ...flags],
});
let status = 0;
const page = await browser.newPage({ viewport: { width: jobs.width, height: jobs.height }, deviceScaleFactor: 1 });
const pageLog = [];
page.on('console', m => pageLog.push(`${m.type()}: ${m.text()}`));
page.on('pageerror', e => pageLog.push(`pageerror: ${e.message}`));
await page.route('**/*', async route => {
    const url = new URL(route.request().url());
    if (url.origin !== origin) return route.abort('blockedbyclient');
    if (url.pathname === '/viewer/gltf-viewer.module.js')
        return route.fulfill({ status: 200, contentType: 'text/javascript', body: moduleText });
    if (url.pathname === '/lut_sheen_E.png')
        return route.fulfill({ status: 200, contentType: 'image/png', body: whitePng() });
    const file = files.get(decodeURIComponent(url.pathname));
    if (!file) {
        pageLog.push(`render.mjs: 404 ${url.pathname}`);
        return route.fulfill({ status: 404, body: 'not found' });
    }
    return route.fulfill({ status: 200, contentType: types[path.extname(file)] || 'application/octet-stream',
                           body: fs.readFileSync(file) });
});
try {
    await page.goto(`${origin}/page.html`);
    await page.waitForFunction(() => window.viewerReady === true, null, { timeout: 60000 });
    const renderer = await page.evaluate(() => {
        const gl = document.createElement('canvas').getContext('webgl2');
        if (!gl) return null;
        const ext = gl.getExtension('WEBGL_debug_renderer_info');
        return ext ? gl.getParameter(ext.UNMASKED_RENDERER_WEBGL) : gl.getParameter(gl.RENDERER);
    });
    if (!renderer) throw new Error('Chromium gave the page no WebGL 2 context (flags: ' + flags.join(' ') + ')');
    // The engine prefilters in float when the context has both (else half float, else 8 bits with values above 1
    // clamped and a global rescale).
    const floats = await page.evaluate(() => {
        const gl = document.createElement('canvas').getContext('webgl2');
        return ['EXT_color_buffer_float', 'OES_texture_float_linear']
            .map(e => `${e} ${gl.getExtension(e) ? 'yes' : 'no'}`);
    });
    console.log(`render.mjs: WebGL 2 renderer: ${renderer}; ${floats.join(', ')}`);
    for (const [i, c] of jobs.cases.entries()) {
        const t0 = Date.now();
        const url = await page.evaluate(options => window.renderCase(options), {
            gltf: `/scenes/${i}/${path.basename(c.gltf)}`, width: jobs.width, height: jobs.height,
            exposure: c.exposure, iblIntensity: c.iblIntensity, lightScale: c.lightScale,
            environmentRotation: c.environmentRotation });
        const viewerLog = await page.evaluate(() => window.viewerLog());
        const errors = viewerLog.filter(l => /^(error|uncaught|unhandled)/.test(l));
        if (errors.length) throw new Error(`${c.gltf}: the viewer reported errors:\n  ${errors.join('\n  ')}`);
        fs.writeFileSync(c.out, Buffer.from(url.slice(url.indexOf(',') + 1), 'base64'));
        console.log(`render.mjs: ${path.basename(c.gltf)} -> ${c.out} (${Date.now() - t0} ms)`);
    }
} catch (e) {
    console.error(`render.mjs: ${e.message}`);
    console.error('page console:\n  ' + pageLog.join('\n  '));
    status = 1;
}
await browser.close();
process.exit(status);
