// Opening graph and variant files (a variant shows its merged graph, as core's loader merges `extends`) and
// writing them back: a graph as the whole document, a variant as the merge patch against its base.
import { applyMergePatch, deepEqual, diffMergePatch } from './mergePatch';
import { formatJson } from './format';
import { stripUi } from './document';
import { dirname, join, relative } from './paths';
import { isObject, Json, JsonObject } from './types';

export type ReadFile = (path: string) => Promise<string>;

export interface OpenFile {
  /** Path relative to DIR. */
  path: string;
  kind: 'graph' | 'variant';
  /** The file's text and JSON as read (or last saved). */
  text: string;
  json: JsonObject;
  /** The merged document of the file (equal to `json` for a graph). */
  merged: JsonObject;
  /** Variant only: the path of its base (relative to DIR) and the base's merged document. */
  basePath?: string;
  baseMerged?: JsonObject;
}

function parseObject(text: string, path: string): JsonObject {
  let v: Json;
  try {
    v = JSON.parse(text) as Json;
  } catch (e) {
    throw new Error(`${path}: ${(e as Error).message}`);
  }
  if (!isObject(v)) throw new Error(`${path}: /: expected a JSON object (a vitrine graph)`);
  return v;
}

/** The merged document of a file and its `extends` chain (without `extends`). */
export async function loadMerged(path: string, read: ReadFile, chain: string[] = []): Promise<JsonObject> {
  if (chain.includes(path)) throw new Error(`${path}: /extends: \`extends\` forms a cycle: ${[...chain, path].join(' -> ')}`);
  const json = parseObject(await read(path), path);
  return mergeFile(json, path, read, [...chain, path]);
}

async function mergeFile(json: JsonObject, path: string, read: ReadFile, chain: string[]): Promise<JsonObject> {
  if (typeof json.extends !== 'string') return json;
  const basePath = join(dirname(path), json.extends);
  const base = await loadMerged(basePath, read, chain);
  const patch = { ...json };
  delete patch.extends;
  return applyMergePatch(base, patch) as JsonObject;
}

export async function openFile(path: string, read: ReadFile): Promise<OpenFile> {
  const text = await read(path);
  const json = parseObject(text, path);
  if (typeof json.extends !== 'string') return { path, kind: 'graph', text, json, merged: json };
  const basePath = join(dirname(path), json.extends);
  const baseMerged = await loadMerged(basePath, read, [path]);
  const patch = { ...json };
  delete patch.extends;
  return {
    path,
    kind: 'variant',
    text,
    json,
    merged: applyMergePatch(baseMerged, patch) as JsonObject,
    basePath,
    baseMerged,
  };
}

/** A variant file's JSON for `doc` (a merged document): `$schema` and `extends` as the file had them, then the patch. */
export function variantJson(
  baseMerged: JsonObject,
  doc: JsonObject,
  head: { $schema?: Json; extends: string },
  previous: JsonObject = {},
): JsonObject {
  const strip = (o: JsonObject) => {
    const c = { ...o };
    delete c.$schema;
    delete c.extends;
    return c;
  };
  const patch = diffMergePatch(strip(baseMerged), strip(doc), strip(previous));
  const out: JsonObject = {};
  const rest = isObject(patch) ? patch : {};
  // Keep the previous file's key order for $schema / extends (the shipped variants put them first).
  const order = Object.keys(previous).length > 0 ? Object.keys(previous) : ['$schema', 'extends'];
  for (const k of order) {
    if (k === '$schema' && head.$schema !== undefined) out.$schema = head.$schema;
    else if (k === 'extends') out.extends = head.extends;
    else if (k in rest) out[k] = rest[k];
  }
  if (head.$schema !== undefined && !('$schema' in out)) out.$schema = head.$schema;
  if (!('extends' in out)) out.extends = head.extends;
  for (const [k, v] of Object.entries(rest)) if (!(k in out)) out[k] = v;
  return out;
}

/** The text to write for the open file holding `doc`: unchanged → the bytes as read. */
export function serializeForSave(file: OpenFile, doc: JsonObject): string {
  if (deepEqual(doc, file.merged)) return file.text;
  if (file.kind === 'graph') return formatJson(doc, { original: file.text });
  const json = variantJson(file.baseMerged!, doc, { $schema: file.json.$schema, extends: file.json.extends as string }, file.json);
  return formatJson(json, { original: file.text });
}

/** The JSON the file would hold (what render/validate requests send as `document`, with `base` = the file). */
export function documentForServer(file: OpenFile, doc: JsonObject): JsonObject {
  if (file.kind === 'graph') return stripUi(doc);
  const json = variantJson(stripUi(file.baseMerged!), stripUi(doc), { extends: file.json.extends as string });
  delete json.$schema;
  return json;
}

/** `$schema` of a file written at `newPath`, pointing at the schema the open file points at. */
export function schemaFor(file: OpenFile, newPath: string): Json | undefined {
  const s = file.merged.$schema;
  if (typeof s !== 'string' || /^[a-z]+:/.test(s)) return s;
  // For a variant, the merged $schema is the variant's own (relative to the variant's folder).
  return relative(dirname(newPath), join(dirname(file.path), s));
}

/** A new variant of the open file, holding only what `doc` changes (plus an optional description). */
export function newVariantText(file: OpenFile, doc: JsonObject, newPath: string, description?: string): string {
  const target = description ? { ...doc, description } : doc;
  const json = variantJson(
    file.merged,
    target,
    { $schema: schemaFor(file, newPath), extends: relative(dirname(newPath), file.path) },
    {},
  );
  if (json.$schema === undefined) delete json.$schema;
  return formatJson(json);
}

/** The whole graph written at a new path (a variant's merged graph becomes a plain graph). */
export function saveAsText(file: OpenFile, doc: JsonObject, newPath: string): string {
  const out: JsonObject = { ...doc };
  delete out.extends;
  const schema = schemaFor(file, newPath);
  if (schema !== undefined) out.$schema = schema;
  return formatJson(out, file.kind === 'graph' && dirname(newPath) === dirname(file.path) ? { original: file.text } : {});
}
