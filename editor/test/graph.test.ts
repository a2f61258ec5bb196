// Unit tests of the editor's document logic (no browser, no server): merge patches as RFC 7386 defines them,
// the file round trip on every shipped graph and variant, the variant a set of edits produces, and the
// graph model (wires, @prev, outputs).
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { readdirSync, readFileSync } from 'node:fs';
import { join } from 'node:path';
import { applyMergePatch, deepEqual, diffMergePatch } from '../src/graph/mergePatch';
import { formatJson, parseWithSpans, pointerTokens } from '../src/graph/format';
import {
  addNode,
  autoLayout,
  checkConnection,
  edgesOf,
  removeNodes,
  setInput,
  setNodePosition,
  setOutputPosition,
  setParam,
  storedPosition,
  stripUi,
  uniqueNodeId,
} from '../src/graph/document';
import { newVariantText, openFile, serializeForSave, variantJson, documentForServer } from '../src/graph/files';
import { dirname, join as pjoin, relative } from '../src/graph/paths';
import { checkParam, hasExtension, paramsSetByInputs, pathExtensions } from '../src/graph/schema';
import type { Json, JsonObject, NodeSchema, ParamSchema } from '../src/graph/types';

const REPO = join(process.cwd(), '..');
const read = async (p: string) => readFileSync(join(REPO, p), 'utf8');
const graphFiles = [
  ...readdirSync(join(REPO, 'graphs'))
    .filter((f) => f.endsWith('.json') && !f.includes('schema'))
    .map((f) => `graphs/${f}`),
  ...readdirSync(join(REPO, 'graphs/variants'))
    .filter((f) => f.endsWith('.json'))
    .map((f) => `graphs/variants/${f}`),
];

test('applyMergePatch follows the RFC 7386 examples', () => {
  const cases: [Json, Json, Json][] = [
    [{ a: 'b' }, { a: 'c' }, { a: 'c' }],
    [{ a: 'b' }, { b: 'c' }, { a: 'b', b: 'c' }],
    [{ a: 'b' }, { a: null }, {}],
    [{ a: 'b', b: 'c' }, { a: null }, { b: 'c' }],
    [{ a: ['b'] }, { a: 'c' }, { a: 'c' }],
    [{ a: 'c' }, { a: ['b'] }, { a: ['b'] }],
    [{ a: { b: 'c' } }, { a: { b: 'd', c: null } }, { a: { b: 'd' } }],
    [{ a: [{ b: 'c' }] }, { a: [1] }, { a: [1] }],
    [['a', 'b'], ['c', 'd'], ['c', 'd']],
    [{ a: 'b' }, ['c'], ['c']],
    [{ a: 'foo' }, null, null],
    [{ a: 'foo' }, 'bar', 'bar'],
    [{ e: null }, { a: 1 }, { e: null, a: 1 }],
    [[1, 2], { a: 'b', c: null }, { a: 'b' }],
    [{}, { a: { bb: { ccc: null } } }, { a: { bb: {} } }],
  ];
  for (const [target, patch, expected] of cases) assert.deepEqual(applyMergePatch(target, patch), expected);
});

test('diffMergePatch gives the smallest patch, deletions as null', () => {
  const base: JsonObject = { nodes: { a: { type: 'x', params: { k: 1 } }, b: { type: 'y' } }, outputs: { final: 'b.color' } };
  const doc: JsonObject = { nodes: { a: { type: 'x', params: { k: 2 } } }, outputs: { final: 'a.color' } };
  const patch = diffMergePatch(base, doc);
  assert.deepEqual(patch, { nodes: { a: { params: { k: 2 } }, b: null }, outputs: { final: 'a.color' } });
  assert.deepEqual(applyMergePatch(base, patch!), doc);
  assert.equal(diffMergePatch(base, base), undefined);
  // A previous patch's redundant entries are kept when they still hold.
  const previous: JsonObject = { format: 'f', nodes: { b: null } };
  assert.deepEqual(diffMergePatch({ format: 'f', nodes: { a: 1, b: 2 } }, { format: 'f', nodes: { a: 1 } }, previous), previous);
});

test('every shipped graph and variant opens, and saving it unedited writes the same bytes', async () => {
  assert.ok(graphFiles.length > 10);
  for (const path of graphFiles) {
    const text = await read(path);
    const file = await openFile(path, read);
    assert.equal(serializeForSave(file, file.merged), text, path);
    // The formatter alone (without the unchanged-file shortcut) reproduces the text from its spans ...
    assert.equal(formatJson(file.json, { original: text }), text, path);
    // ... and without the original it still writes the same JSON.
    assert.deepEqual(JSON.parse(formatJson(file.json)), JSON.parse(text), path);
    if (file.kind === 'variant') {
      // The patch recomputed from the merged graph and the file is the file (same JSON, same key order).
      const again = variantJson(file.baseMerged!, file.merged, { $schema: file.json.$schema, extends: file.json.extends as string }, file.json);
      assert.deepEqual(again, file.json, path);
      assert.deepEqual(Object.keys(again), Object.keys(file.json), path);
      // Without the file to go by, the patch is minimal but merges to the same graph.
      const minimal = variantJson(file.baseMerged!, file.merged, { extends: file.json.extends as string });
      const patch = { ...minimal };
      delete patch.extends;
      assert.ok(deepEqual(applyMergePatch(file.baseMerged!, patch), { ...file.merged, $schema: file.baseMerged!.$schema }), path);
    }
  }
});

test('fxaa_zoneplate.json is written exactly as the file even without its original text', async () => {
  const text = await read('graphs/fxaa_zoneplate.json');
  assert.equal(formatJson(JSON.parse(text) as Json), text);
});

test('an edited graph changes only the lines of what was edited', async () => {
  const path = 'graphs/museum.json';
  const text = await read(path);
  const file = await openFile(path, read);
  const doc = setParam(file.merged, 'grain', 'strength', 0.02);
  const out = serializeForSave(file, doc);
  assert.deepEqual(JSON.parse(out), doc);
  const a = text.split('\n');
  const b = out.split('\n');
  assert.equal(a.length, b.length);
  const changed = b.filter((line, i) => line !== a[i]);
  assert.equal(changed.length, 1, changed.join('\n'));
  assert.match(changed[0], /"grain".*"strength": 0.02, "size": 1.0\}/);
});

test('deleting FXAA and rewiring, saved as a variant, is graphs/variants/no_fxaa.json', async () => {
  const file = await openFile('graphs/fxaa_zoneplate.json', read);
  let doc = removeNodes(file.merged, ['fxaa']);
  assert.deepEqual(Object.keys((doc.nodes as JsonObject).tonemap as JsonObject).includes('in'), false);
  doc = setInput(doc, 'tonemap', 'color', { node: 'pattern', port: 'color', prev: false });
  const expected = JSON.parse(await read('graphs/variants/no_fxaa.json')) as JsonObject;
  const written = JSON.parse(newVariantText(file, doc, 'graphs/variants/no_fxaa.json', expected.description as string));
  assert.deepEqual(written, expected);
  const plain = JSON.parse(newVariantText(file, doc, 'graphs/variants/no_fxaa.json'));
  delete expected.description;
  assert.deepEqual(plain, expected);
});

test('a variant opens merged (a null deletes a node) and is saved as its patch', async () => {
  const file = await openFile('graphs/variants/museum_no_grain.json', read);
  assert.equal(file.kind, 'variant');
  assert.equal(file.basePath, 'graphs/museum.json');
  const nodes = file.merged.nodes as JsonObject;
  assert.ok(!('grain' in nodes));
  assert.ok('grade' in nodes);
  assert.equal((file.merged.outputs as JsonObject).final, 'grade.color');
  const doc = setParam(file.merged, 'grade', 'saturation', 0.9);
  const saved = JSON.parse(serializeForSave(file, doc)) as JsonObject;
  assert.deepEqual(saved, { ...file.json, nodes: { grain: null, grade: { params: { saturation: 0.9 } } } });
  // What render/validate requests carry for it: the patch with extends, no ui.
  const sent = documentForServer(file, doc);
  assert.equal(sent.extends, '../museum.json');
  assert.deepEqual(sent.nodes, { grain: null, grade: { params: { saturation: 0.9 } } });
});

test('wires, @prev links and graph outputs come from the document', async () => {
  const file = await openFile('graphs/museum.json', read);
  const edges = edgesOf(file.merged);
  const prev = edges.filter((e) => e.prev);
  assert.ok(prev.some((e) => e.source === 'gfilter' && e.sourcePort === 'history' && e.target === 'gfilter' && e.targetPort === 'history'));
  assert.ok(edges.some((e) => e.target === 'output:final' && e.targetPort === 'value'));
  const layout = autoLayout(file.merged, new Map());
  assert.equal(layout.size, Object.keys(file.merged.nodes as JsonObject).length + Object.keys(file.merged.outputs as JsonObject).length);
});

test('added nodes get unique ids and a ui position that stripUi removes', async () => {
  const file = await openFile('graphs/fxaa_zoneplate.json', read);
  assert.equal(uniqueNodeId(file.merged, 'aa.fxaa'), 'fxaa2');
  assert.equal(uniqueNodeId(file.merged, 'post.grain'), 'grain');
  const doc = addNode(file.merged, 'grain', 'post.grain', { x: 10.4, y: 20.6 });
  assert.deepEqual((doc.nodes as JsonObject).grain, { type: 'post.grain', ui: { x: 10, y: 21 } });
  assert.deepEqual((stripUi(doc).nodes as JsonObject).grain, { type: 'post.grain' });
});

test('paths, JSON pointers and spans', () => {
  assert.equal(relative('graphs/variants', 'graphs/fxaa_zoneplate.json'), '../fxaa_zoneplate.json');
  assert.equal(relative('graphs', 'data/luts/x.cube'), '../data/luts/x.cube');
  assert.equal(pjoin('graphs/variants', '../museum.json'), 'graphs/museum.json');
  assert.equal(dirname('graphs/x.json'), 'graphs');
  assert.deepEqual(pointerTokens('/nodes/a~1b/params/k~0'), ['nodes', 'a/b', 'params', 'k~']);
  const { spans } = parseWithSpans('{"a": {"b": 6.0}}');
  assert.equal(spans.get('/a/b')!.start, 12);
});

test('client-side param checks follow the schema', () => {
  const f: ParamSchema = { name: 'subpix', type: 'float', default: 0.75, min: 0, max: 1 };
  assert.equal(checkParam(f, 0.5), null);
  assert.match(checkParam(f, 5)!, /in \[0, 1\]/);
  assert.match(checkParam(f, 'x')!, /expected a number/);
  const i: ParamSchema = { name: 'n', type: 'int', default: 1, min: 1, max: 12 };
  assert.match(checkParam(i, 1.5)!, /integer/);
  const e: ParamSchema = { name: 'm', type: 'enum', default: 'a', choices: ['a', 'b'] };
  assert.equal(checkParam(e, 'b'), null);
  assert.match(checkParam(e, 'c')!, /one of a, b/);
  const v: ParamSchema = { name: 'c', type: 'vec3', default: [0, 0, 0] };
  assert.equal(checkParam(v, [1, 2, 3]), null);
  assert.ok(checkParam(v, [1, 2]));
});

// A few node schemas, written out as `vitrine nodes --json` gives them.
const SCHEMAS = new Map(
  [
    { type: 'pattern.zoneplate', inputs: [], outputs: [{ name: 'color', kind: 'texture' }], params: [] },
    { type: 'aa.fxaa', inputs: [{ name: 'color', kind: 'texture' }], outputs: [{ name: 'color', kind: 'texture' }], params: [] },
    {
      type: 'post.tonemap',
      inputs: [
        { name: 'color', kind: 'texture' },
        { name: 'camera_state', kind: 'buffer', optional: true },
      ],
      outputs: [{ name: 'color', kind: 'texture' }],
      params: [],
    },
    { type: 'scene.museum', inputs: [], outputs: [{ name: 'scene', kind: 'scene' }, { name: 'camera', kind: 'camera' }], params: [] },
  ].map((s) => [s.type, s as NodeSchema]),
);

test('connections: kinds must match, a wire back upstream is an @prev link (textures only)', async () => {
  const file = await openFile('graphs/fxaa_zoneplate.json', read);
  const doc = addNode(file.merged, 'scene', 'scene.museum', { x: 0, y: 0 });
  const ok = checkConnection(doc, SCHEMAS, 'pattern', 'color', 'tonemap', 'color');
  assert.deepEqual(ok, { ok: true, ref: { node: 'pattern', port: 'color', prev: false }, target: 'tonemap', port: 'color' });
  const kind = checkConnection(doc, SCHEMAS, 'scene', 'scene', 'fxaa', 'color');
  assert.equal(kind.ok, false);
  assert.match((kind as { message: string }).message, /takes a texture, but scene.scene is a scene/);
  const buffer = checkConnection(doc, SCHEMAS, 'pattern', 'color', 'tonemap', 'camera_state');
  assert.equal(buffer.ok, false);
  // tonemap reads fxaa this frame: tonemap.color → fxaa.color closes a cycle, so it reads last frame's value.
  const back = checkConnection(doc, SCHEMAS, 'tonemap', 'color', 'fxaa', 'color');
  assert.deepEqual(back.ok && back.ref, { node: 'tonemap', port: 'color', prev: true });
  const self = checkConnection(doc, SCHEMAS, 'fxaa', 'color', 'fxaa', 'color');
  assert.deepEqual(self.ok && self.ref, { node: 'fxaa', port: 'color', prev: true });
  const output = checkConnection(doc, SCHEMAS, 'fxaa', 'color', 'output:final', 'value');
  assert.equal(output.ok && output.output, 'final');
  assert.equal(checkConnection(doc, SCHEMAS, 'scene', 'camera', 'output:final', 'value').ok, false);
  const prevDoc = setInput(doc, 'fxaa', 'color', { node: 'tonemap', port: 'color', prev: true });
  assert.deepEqual(((prevDoc.nodes as JsonObject).fxaa as JsonObject).in, { color: 'tonemap.color@prev' });
});

test('moved nodes keep their positions in the ui block across save and open', async () => {
  const path = 'graphs/fxaa_zoneplate.json';
  const file = await openFile(path, read);
  let doc = setNodePosition(file.merged, 'fxaa', { x: 300.4, y: -20 });
  doc = setOutputPosition(doc, 'final', { x: 900, y: 0 });
  const text = serializeForSave(file, doc);
  const again = await openFile(path, async () => text);
  assert.deepEqual(storedPosition(again.merged, 'fxaa'), { x: 300, y: -20 });
  assert.deepEqual(storedPosition(again.merged, 'output:final'), { x: 900, y: 0 });
  assert.equal(storedPosition(again.merged, 'pattern'), undefined);
  // The renderer never sees them.
  assert.deepEqual(stripUi(again.merged), file.merged);
});

test('path pickers ask for the extensions a path param documents', () => {
  const spec = (doc: string) => ({ name: 'p', type: 'path', doc }) as unknown as Parameters<typeof pathExtensions>[0];
  assert.deepEqual(pathExtensions(spec('LUT file OCIO can read (.cube, .3dl, .csp, ...): a bare file name is one of data/luts/ (warm_film.cube)')), ['.3dl', '.csp', '.cube']);
  assert.deepEqual(pathExtensions(spec('The .gltf or .glb file (relative to the graph file)')), ['.glb', '.gltf']);
  assert.deepEqual(pathExtensions(spec('Reflection probes from a JSON file {"probes": [...]} (relative to the graph file)')), ['.json']);
  assert.deepEqual(pathExtensions(spec('Image file, relative to the graph file')), ['.bmp', '.exr', '.hdr', '.jpeg', '.jpg', '.png', '.tga']);
  assert.deepEqual(pathExtensions(spec('Anything')), []);
  assert.equal(hasExtension('data/luts/Warm.CUBE', ['.cube']), true);
  assert.equal(hasExtension('data/luts/warm.png', ['.cube']), false);
  assert.equal(hasExtension('x.bin', []), true);
});

test('params a connected input replaces, from the input docs (the nodes\' wording)', () => {
  const param = (name: string): ParamSchema => ({ name, type: 'float', default: 0 });
  const schema = (inputs: [string, string][], params: string[]): NodeSchema => ({
    type: 't',
    inputs: inputs.map(([name, doc]) => ({ name, doc, kind: 'buffer' }) as unknown as NodeSchema['inputs'][number]),
    outputs: [],
    params: params.map(param),
  });
  // post.tonemap's and post.grain's docs as `vitrine nodes --json` prints them.
  const tonemap = schema(
    [
      ['color', 'Linear HDR colour'],
      ['camera_state', "camera.physical's state: when connected, its exposure replaces the `exposure` param"],
    ],
    ['exposure', 'operator', 'inverse'],
  );
  assert.deepEqual([...paramsSetByInputs(tonemap)], [['exposure', 'camera_state']]);
  const grain = schema([['camera_state', "camera.physical's state: when connected, its ISO replaces the `iso` param"]], ['iso', 'amount']);
  assert.deepEqual([...paramsSetByInputs(grain)], [['iso', 'camera_state']]);
  // Several names; a name the node has no param of is left out; no wording, no entry.
  const several = schema([['cam', 'replaces the `a`, `b` and `zz` params']], ['a', 'b', 'c']);
  assert.deepEqual([...paramsSetByInputs(several)].sort(), [['a', 'cam'], ['b', 'cam']]);
  assert.equal(paramsSetByInputs(schema([['color', 'Linear HDR colour']], ['exposure'])).size, 0);
  assert.equal(paramsSetByInputs(undefined).size, 0);
});
