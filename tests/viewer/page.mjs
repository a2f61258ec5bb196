// The Sample Viewer side of ctest gltf.sample_viewer (see check_viewer.py): window.renderCase(options) loads the
// studio environment and one glTF file into @khronosgroup/gltf-viewer and renders one frame through the file's camera;
// it resolves to the canvas as a PNG data: URL.
import { GltfState, GltfView } from '/viewer/gltf-viewer.module.js';

const log = [];
for (const level of ['log', 'warn', 'error']) {
    const original = console[level].bind(console);
    console[level] = (...args) => {
        log.push(`${level}: ${args.map(a => (a instanceof Error ? a.stack : String(a))).join(' ')}`);
        original(...args);
    };
}
window.addEventListener('error', e => log.push(`uncaught: ${e.message}`));
window.addEventListener('unhandledrejection', e => log.push(`unhandled rejection: ${e.reason}`));
window.viewerLog = () => log.splice(0);

// Draco is not in the package (a CDN library); none of the files is Draco-compressed, so the decoder gets an empty
// module it never calls.
const noDraco = module => module.onModuleLoaded({});

let view = null;
let loader = null;
let environment = null;

window.renderCase = async ({ gltf, width, height, exposure, iblIntensity, lightScale, environmentRotation }) => {
    const canvas = document.getElementById('canvas');
    canvas.width = width;
    canvas.height = height;
    if (!view) {
        const gl = canvas.getContext('webgl2', { preserveDrawingBuffer: true, alpha: false, antialias: true });
        if (!gl) throw new Error('no WebGL 2 context');
        view = new GltfView(gl);
        loader = view.createResourceLoader(noDraco, undefined, '/viewer/libs/');
        // The engine prefilters the equirectangular .hdr itself (Lambertian, GGX and Charlie cube maps, GGX LUT).
        // The sheen albedo LUT is a file it does not ship: render.mjs serves a neutral one (no file here uses sheen).
        environment = await loader.loadEnvironment('/env/studio.hdr', { lut_sheen_E_file: '/lut_sheen_E.png' });
        if (!environment) throw new Error('loadEnvironment failed: ' + log.join('\n'));
    }
    const state = view.createState();
    state.environment = environment;
    state.gltf = await loader.loadGltf(gltf);
    state.sceneIndex = state.gltf.scene ?? 0;
    state.cameraIndex = 0; // the file's camera (node "camera")
    const p = state.renderingParameters;
    p.toneMap = GltfState.ToneMaps.KHR_PBR_NEUTRAL;
    p.exposure = exposure;
    p.iblIntensity = iblIntensity;
    p.usePunctual = true;
    p.useIBL = true;
    p.renderEnvironmentMap = true;
    p.blurEnvironmentMap = false;
    p.environmentRotation = environmentRotation;
    for (const light of state.gltf.lights ?? []) light.intensity = light.intensity * lightScale;
    // Textures upload on first use: a few frames, then the one read back.
    for (let i = 0; i < 3; ++i) {
        view.renderFrame(state, width, height);
        await new Promise(r => requestAnimationFrame(r));
    }
    view.renderFrame(state, width, height);
    view.context.finish();
    return canvas.toDataURL('image/png');
};
window.viewerReady = true;
