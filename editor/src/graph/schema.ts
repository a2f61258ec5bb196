// Client-side checks of param values against the node schemas (the same rules as core's checkParam), and
// helpers the widgets use.
import { isObject, Json, NodeSchema, ParamSchema, SchemaMap } from './types';

export function schemaMap(list: NodeSchema[]): SchemaMap {
  return new Map(list.map((s) => [s.type, s]));
}

export function vectorSize(type: string): number {
  return type === 'vec2' ? 2 : type === 'vec3' ? 3 : type === 'vec4' ? 4 : 0;
}

function range(spec: ParamSchema): string {
  return spec.min !== undefined && spec.max !== undefined ? ` in [${spec.min}, ${spec.max}]` : '';
}

function inRange(spec: ParamSchema, v: number): boolean {
  return (spec.min === undefined || v >= spec.min) && (spec.max === undefined || v <= spec.max);
}

/** null when `value` is valid for `spec`, else what was expected. */
export function checkParam(spec: ParamSchema, value: Json): string | null {
  switch (spec.type) {
    case 'int':
      return typeof value === 'number' && Number.isInteger(value) && inRange(spec, value)
        ? null
        : `expected an integer${range(spec)}, got ${JSON.stringify(value)}`;
    case 'float':
      return typeof value === 'number' && Number.isFinite(value) && inRange(spec, value)
        ? null
        : `expected a number${range(spec)}, got ${JSON.stringify(value)}`;
    case 'bool':
      return typeof value === 'boolean' ? null : `expected true or false, got ${JSON.stringify(value)}`;
    case 'enum':
      return typeof value === 'string' && (spec.choices ?? []).includes(value)
        ? null
        : `expected one of ${(spec.choices ?? []).join(', ')}, got ${JSON.stringify(value)}`;
    case 'string':
    case 'path':
      return typeof value === 'string' ? null : `expected a string, got ${JSON.stringify(value)}`;
    default: {
      const n = vectorSize(spec.type);
      const ok =
        Array.isArray(value) &&
        value.length === n &&
        value.every((x) => typeof x === 'number' && Number.isFinite(x) && inRange(spec, x));
      return ok ? null : `expected ${n} numbers${range(spec)}, got ${JSON.stringify(value)}`;
    }
  }
}

/** Vectors shown with a colour swatch: by name (color, colour, tint, albedo). */
export function isColorParam(spec: ParamSchema): boolean {
  return (spec.type === 'vec3' || spec.type === 'vec4') && /colou?r|tint|albedo|rgb/i.test(spec.name);
}

/** The `type` prefix used to group the palette: `post.grain` → `post`. */
export function typeGroup(type: string): string {
  const i = type.indexOf('.');
  return i < 0 ? type : type.slice(0, i);
}

/** The schema's errors for every param of a node's `params` object, keyed by param name. */
export function paramErrors(schema: NodeSchema | undefined, params: Json | undefined): Map<string, string> {
  const errors = new Map<string, string>();
  if (!schema || !isObject(params)) return errors;
  for (const [key, value] of Object.entries(params)) {
    const spec = schema.params.find((p) => p.name === key);
    if (!spec) errors.set(key, `node type ${schema.type} has no param '${key}'`);
    else {
      const e = checkParam(spec, value);
      if (e) errors.set(key, e);
    }
  }
  return errors;
}

const FILE_EXTENSIONS = new Set(['cube', '3dl', 'csp', 'spi1d', 'spi3d', 'clf', 'hdr', 'exr', 'png', 'jpg', 'jpeg', 'tga', 'bmp', 'ktx', 'ktx2', 'gltf', 'glb', 'json']);
const IMAGE_EXTENSIONS = ['png', 'jpg', 'jpeg', 'exr', 'hdr', 'tga', 'bmp'];

/** The file extensions a path param takes (for the picker's `GET /api/files?ext=`), from what its doc names
 *  (".cube, .3dl", ".gltf or .glb", "JSON file", "Image file"); empty: any file. */
export function pathExtensions(spec: ParamSchema): string[] {
  const doc = spec.doc ?? '';
  const found = new Set<string>();
  for (const m of doc.matchAll(/\.([A-Za-z0-9]{2,5})\b/g)) {
    const ext = m[1].toLowerCase();
    if (FILE_EXTENSIONS.has(ext)) found.add(ext);
  }
  if (/\bJSON\b/.test(doc)) found.add('json');
  if (found.size === 0 && /\bimage\b/i.test(doc)) for (const e of IMAGE_EXTENSIONS) found.add(e);
  return [...found].sort().map((e) => `.${e}`);
}

/** Whether `path` ends with one of `extensions` (any when empty; case-insensitive). */
export function hasExtension(path: string, extensions: string[]): boolean {
  const lower = path.toLowerCase();
  return extensions.length === 0 || extensions.some((e) => lower.endsWith(e));
}

/** The params a connected input replaces, param name → input name: what an input's doc says it replaces
 *  ("when connected, its exposure replaces the `exposure` param"; backquoted names, the nodes' convention). */
export function paramsSetByInputs(schema: NodeSchema | undefined): Map<string, string> {
  const replaced = new Map<string, string>();
  for (const input of schema?.inputs ?? []) {
    const m = (input.doc ?? '').match(/replaces the ((?:`[A-Za-z0-9_]+`(?:,? (?:and )?)?)+) params?\b/);
    if (!m) continue;
    for (const name of m[1].matchAll(/`([A-Za-z0-9_]+)`/g))
      if (schema!.params.some((p) => p.name === name[1])) replaced.set(name[1], input.name);
  }
  return replaced;
}
