// The graph document (the file's JSON, merged with its bases for a variant) and the edits the editor makes on
// it. Every edit returns a new document; the document is the only state that is saved.
import { clone } from './mergePatch';
import { isObject, Json, JsonObject, PortRef, Position, SchemaMap } from './types';

export const REF_PATTERN = /^([A-Za-z_][A-Za-z0-9_]*)\.([A-Za-z_][A-Za-z0-9_]*)(@prev)?$/;
export const NODE_ID_PATTERN = /^[A-Za-z_][A-Za-z0-9_]*$/;

export function parseRef(text: Json | undefined): PortRef | null {
  if (typeof text !== 'string') return null;
  const m = REF_PATTERN.exec(text);
  return m ? { node: m[1], port: m[2], prev: m[3] !== undefined } : null;
}

export function formatRef(ref: PortRef): string {
  return `${ref.node}.${ref.port}${ref.prev ? '@prev' : ''}`;
}

export function nodesOf(doc: JsonObject): JsonObject {
  return isObject(doc.nodes) ? doc.nodes : {};
}

export function outputsOf(doc: JsonObject): JsonObject {
  return isObject(doc.outputs) ? doc.outputs : {};
}

export function nodeEntry(doc: JsonObject, id: string): JsonObject | undefined {
  const n = nodesOf(doc)[id];
  return isObject(n) ? n : undefined;
}

export function nodeType(doc: JsonObject, id: string): string {
  const t = nodeEntry(doc, id)?.type;
  return typeof t === 'string' ? t : '';
}

export function nodeInputs(doc: JsonObject, id: string): JsonObject {
  const n = nodeEntry(doc, id);
  return n && isObject(n.in) ? n.in : {};
}

export function nodeParams(doc: JsonObject, id: string): JsonObject {
  const n = nodeEntry(doc, id);
  return n && isObject(n.params) ? n.params : {};
}

export interface GraphEdge {
  id: string;
  source: string;
  sourcePort: string;
  /** A node id, or `output:<name>` for a graph output. */
  target: string;
  targetPort: string;
  prev: boolean;
}

export const OUTPUT_PREFIX = 'output:';

export function edgesOf(doc: JsonObject): GraphEdge[] {
  const edges: GraphEdge[] = [];
  for (const id of Object.keys(nodesOf(doc))) {
    for (const [port, text] of Object.entries(nodeInputs(doc, id))) {
      const r = parseRef(text);
      if (!r || !nodeEntry(doc, r.node)) continue;
      edges.push({ id: `${id}.${port}`, source: r.node, sourcePort: r.port, target: id, targetPort: port, prev: r.prev });
    }
  }
  for (const [name, text] of Object.entries(outputsOf(doc))) {
    const r = parseRef(text);
    if (!r || !nodeEntry(doc, r.node)) continue;
    edges.push({
      id: `${OUTPUT_PREFIX}${name}`,
      source: r.node,
      sourcePort: r.port,
      target: `${OUTPUT_PREFIX}${name}`,
      targetPort: 'value',
      prev: false,
    });
  }
  return edges;
}

function withNode(doc: JsonObject, id: string, update: (node: JsonObject) => JsonObject): JsonObject {
  const nodes = nodesOf(doc);
  const node = nodes[id];
  if (!isObject(node)) return doc;
  return { ...doc, nodes: { ...nodes, [id]: update({ ...node }) } };
}

/** Sets (or with `undefined`, removes) param `key` of node `id`; an emptied `params` object is dropped. */
export function setParam(doc: JsonObject, id: string, key: string, value: Json | undefined): JsonObject {
  return withNode(doc, id, (node) => {
    const params = { ...(isObject(node.params) ? node.params : {}) };
    if (value === undefined) delete params[key];
    else params[key] = value;
    if (Object.keys(params).length === 0 && value === undefined) delete node.params;
    else node.params = params;
    return node;
  });
}

/** Connects input `port` of node `id` to `ref` (or disconnects it with null). */
export function setInput(doc: JsonObject, id: string, port: string, ref: PortRef | null): JsonObject {
  return withNode(doc, id, (node) => {
    const inputs = { ...(isObject(node.in) ? node.in : {}) };
    if (ref) inputs[port] = formatRef(ref);
    else delete inputs[port];
    if (Object.keys(inputs).length === 0) delete node.in;
    else node.in = inputs;
    return node;
  });
}

export function setOutput(doc: JsonObject, name: string, ref: PortRef | null): JsonObject {
  const outputs = { ...outputsOf(doc) };
  if (ref) outputs[name] = formatRef({ ...ref, prev: false });
  else delete outputs[name];
  return { ...doc, outputs };
}

export function setNodePosition(doc: JsonObject, id: string, pos: Position): JsonObject {
  return withNode(doc, id, (node) => {
    const ui = isObject(node.ui) ? { ...node.ui } : {};
    ui.x = Math.round(pos.x);
    ui.y = Math.round(pos.y);
    node.ui = ui;
    return node;
  });
}

/** Graph outputs keep their positions in the top-level `ui` block: `"ui": {"outputs": {"final": {"x", "y"}}}`. */
export function setOutputPosition(doc: JsonObject, name: string, pos: Position): JsonObject {
  const ui = isObject(doc.ui) ? { ...doc.ui } : {};
  const outputs = isObject(ui.outputs) ? { ...ui.outputs } : {};
  outputs[name] = { x: Math.round(pos.x), y: Math.round(pos.y) };
  ui.outputs = outputs;
  return { ...doc, ui };
}

export function storedPosition(doc: JsonObject, flowId: string): Position | undefined {
  let ui: Json | undefined;
  if (flowId.startsWith(OUTPUT_PREFIX)) {
    const top = isObject(doc.ui) ? doc.ui : undefined;
    const outs = top && isObject(top.outputs) ? top.outputs : undefined;
    ui = outs?.[flowId.slice(OUTPUT_PREFIX.length)];
  } else {
    ui = nodeEntry(doc, flowId)?.ui;
  }
  if (isObject(ui) && typeof ui.x === 'number' && typeof ui.y === 'number') return { x: ui.x, y: ui.y };
  return undefined;
}

/** A fresh node id from a type: `post.grain` → `grain`, then `grain2`, `grain3`, … */
export function uniqueNodeId(doc: JsonObject, type: string): string {
  const stem = (type.split('.').pop() ?? 'node').replace(/[^A-Za-z0-9_]/g, '_').replace(/^(\d)/, '_$1') || 'node';
  const nodes = nodesOf(doc);
  if (!(stem in nodes)) return stem;
  for (let i = 2; ; i++) if (!(`${stem}${i}` in nodes)) return `${stem}${i}`;
}

export function addNode(doc: JsonObject, id: string, type: string, pos: Position): JsonObject {
  const node: JsonObject = { type, ui: { x: Math.round(pos.x), y: Math.round(pos.y) } };
  return { ...doc, nodes: { ...nodesOf(doc), [id]: node } };
}

/** Removes nodes and every input and graph output that read them. */
export function removeNodes(doc: JsonObject, ids: string[]): JsonObject {
  const gone = new Set(ids);
  let out: JsonObject = { ...doc, nodes: Object.fromEntries(Object.entries(nodesOf(doc)).filter(([k]) => !gone.has(k))) };
  for (const id of Object.keys(nodesOf(out)))
    for (const [port, text] of Object.entries(nodeInputs(out, id))) {
      const r = parseRef(text);
      if (r && gone.has(r.node)) out = setInput(out, id, port, null);
    }
  for (const [name, text] of Object.entries(outputsOf(out))) {
    const r = parseRef(text);
    if (r && gone.has(r.node)) out = setOutput(out, name, null);
  }
  return out;
}

/** The nodes `id` reads, directly or not, this frame or (through @prev) the last. Includes `id`. */
export function upstreamOf(doc: JsonObject, id: string): Set<string> {
  const seen = new Set<string>();
  const stack = [id];
  while (stack.length > 0) {
    const n = stack.pop()!;
    if (seen.has(n) || !nodeEntry(doc, n)) continue;
    seen.add(n);
    for (const text of Object.values(nodeInputs(doc, n))) {
      const r = parseRef(text);
      if (r) stack.push(r.node);
    }
  }
  return seen;
}

/** Whether `from` is reachable from `to`'s inputs this frame (so `from → to` would close a cycle). */
export function readsThisFrame(doc: JsonObject, reader: string, node: string): boolean {
  const seen = new Set<string>();
  const stack = [reader];
  while (stack.length > 0) {
    const n = stack.pop()!;
    if (n === node) return true;
    if (seen.has(n)) continue;
    seen.add(n);
    for (const text of Object.values(nodeInputs(doc, n))) {
      const r = parseRef(text);
      if (r && !r.prev) stack.push(r.node);
    }
  }
  return false;
}

export type ConnectResult =
  | { ok: true; ref: PortRef; target: string; port: string; output?: string }
  | { ok: false; message: string };

/**
 * What a wire from `source.sourcePort` to `target.targetPort` means (target `output:NAME` is a graph output):
 * the kinds must match; a wire back into a node that (already) feeds the source reads last frame's value, an
 * `@prev` history link, which only textures have.
 */
export function checkConnection(
  doc: JsonObject,
  schemas: SchemaMap,
  source: string,
  sourcePort: string,
  target: string,
  targetPort: string,
): ConnectResult {
  const sourceKind = schemas.get(nodeType(doc, source))?.outputs.find((o) => o.name === sourcePort)?.kind;
  if (!sourceKind) return { ok: false, message: `refused: ${source} has no output '${sourcePort}'` };
  if (target.startsWith(OUTPUT_PREFIX)) {
    const name = target.slice(OUTPUT_PREFIX.length);
    if (sourceKind !== 'texture')
      return { ok: false, message: `refused: graph output '${name}' takes a texture, but ${source}.${sourcePort} is a ${sourceKind}` };
    return { ok: true, ref: { node: source, port: sourcePort, prev: false }, target, port: 'value', output: name };
  }
  const input = schemas.get(nodeType(doc, target))?.inputs.find((i) => i.name === targetPort);
  if (!input) return { ok: false, message: `refused: ${target} has no input '${targetPort}'` };
  if (input.kind !== sourceKind)
    return { ok: false, message: `refused: input ${target}.${input.name} takes a ${input.kind}, but ${source}.${sourcePort} is a ${sourceKind}` };
  const prev = source === target || readsThisFrame(doc, source, target);
  if (prev && sourceKind !== 'texture')
    return {
      ok: false,
      message: `refused: ${source}.${sourcePort} → ${target}.${input.name} would form a cycle, and only textures keep last frame's value`,
    };
  return { ok: true, ref: { node: source, port: sourcePort, prev }, target, port: input.name };
}

/** The document without editor state (`ui` blocks), as the renderer sees it. */
export function stripUi(doc: JsonObject): JsonObject {
  const out: JsonObject = { ...doc };
  delete out.ui;
  if (isObject(doc.nodes)) {
    const nodes: JsonObject = {};
    for (const [id, n] of Object.entries(doc.nodes)) {
      if (isObject(n)) {
        const copy = { ...n };
        delete copy.ui;
        nodes[id] = copy;
      } else nodes[id] = n;
    }
    out.nodes = nodes;
  }
  return out;
}

/** Estimated card height (for the automatic layout; React Flow measures the real one). */
export function cardHeight(doc: JsonObject, id: string, schemas: SchemaMap): number {
  const s = schemas.get(nodeType(doc, id));
  if (!s) return 80;
  const textures = s.outputs.filter((o) => o.kind === 'texture').length;
  return 48 + s.inputs.length * 22 + s.outputs.length * 22 + textures * 96;
}

/**
 * Positions for nodes without a stored `ui` position: columns by longest path from the sources (this frame's
 * inputs only; a graph output one column right of what it shows), stacked by estimated card height. A long
 * chain (the museum's ~25 stages) wraps into bands of columns, so that the whole graph is about as wide as
 * high on screen rather than one very long row.
 */
export function autoLayout(doc: JsonObject, schemas: SchemaMap, aspect = 1.6): Map<string, Position> {
  const ids = Object.keys(nodesOf(doc));
  const depth = new Map<string, number>();
  const visiting = new Set<string>();
  const depthOf = (id: string): number => {
    const known = depth.get(id);
    if (known !== undefined) return known;
    if (visiting.has(id)) return 0;
    visiting.add(id);
    let d = 0;
    for (const text of Object.values(nodeInputs(doc, id))) {
      const r = parseRef(text);
      if (r && !r.prev && nodeEntry(doc, r.node)) d = Math.max(d, depthOf(r.node) + 1);
    }
    visiting.delete(id);
    depth.set(id, d);
    return d;
  };
  ids.forEach(depthOf);
  const items: { id: string; d: number; h: number }[] = ids.map((id) => ({ id, d: depth.get(id) ?? 0, h: cardHeight(doc, id, schemas) }));
  for (const name of Object.keys(outputsOf(doc))) {
    const r = parseRef(outputsOf(doc)[name]);
    items.push({ id: `${OUTPUT_PREFIX}${name}`, d: r && depth.has(r.node) ? depth.get(r.node)! + 1 : 0, h: 40 });
  }
  const layerItems: { id: string; h: number }[][] = [];
  for (const it of items) (layerItems[it.d] ??= []).push(it);
  // A layer taller than `maxColumn` (the museum's dozen debug views) is split into several columns.
  const maxColumn = 1100;
  const columns: { id: string; h: number }[][] = [];
  for (const layer of layerItems) {
    let col: { id: string; h: number }[] = [];
    let height = 0;
    for (const it of layer ?? []) {
      if (col.length > 0 && height + it.h > maxColumn) {
        columns.push(col);
        col = [];
        height = 0;
      }
      col.push(it);
      height += it.h + 30;
    }
    columns.push(col);
  }
  const colHeight = (c: { h: number }[] | undefined) => (c ?? []).reduce((sum, it) => sum + it.h + 30, 0);
  const colWidth = 280;
  const bandGap = 80;
  const layers = columns.length;
  // Columns per band: the count whose bounding box is closest to the wanted aspect ratio.
  let perBand = layers;
  let best = Infinity;
  for (let n = 1; n <= layers; n++) {
    let height = 0;
    for (let b = 0; b < layers; b += n) height += Math.max(...columns.slice(b, b + n).map(colHeight)) + bandGap;
    const score = Math.abs(Math.log((n * colWidth) / Math.max(height, 1) / aspect));
    if (score < best) {
      best = score;
      perBand = n;
    }
  }
  const pos = new Map<string, Position>();
  let bandY = 0;
  for (let b = 0; b < layers; b += perBand) {
    const band = columns.slice(b, b + perBand);
    band.forEach((col, i) => {
      let y = bandY;
      for (const it of col ?? []) {
        pos.set(it.id, { x: i * colWidth, y });
        y += it.h + 30;
      }
    });
    bandY += Math.max(...band.map(colHeight)) + bandGap;
  }
  return pos;
}

export function cloneDoc(doc: JsonObject): JsonObject {
  return clone(doc);
}
