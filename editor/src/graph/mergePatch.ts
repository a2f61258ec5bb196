// JSON Merge Patch (RFC 7386 / 7396), as core's loader applies `extends` (nlohmann::json::merge_patch), and the
// inverse: the smallest patch that turns a base into a document, keeping a previous patch's wording where it
// still holds (so re-saving an unchanged variant keeps its redundant entries and key order).
import { isObject, Json, JsonObject } from './types';

export function clone<T extends Json>(v: T): T {
  return v === undefined ? v : (JSON.parse(JSON.stringify(v)) as T);
}

export function deepEqual(a: Json | undefined, b: Json | undefined): boolean {
  if (a === b) return true;
  if (typeof a !== typeof b || a === null || b === null || a === undefined || b === undefined) return false;
  if (Array.isArray(a) || Array.isArray(b)) {
    if (!Array.isArray(a) || !Array.isArray(b) || a.length !== b.length) return false;
    return a.every((x, i) => deepEqual(x, b[i]));
  }
  if (typeof a === 'object' && typeof b === 'object') {
    const ka = Object.keys(a);
    const kb = Object.keys(b as JsonObject);
    if (ka.length !== kb.length) return false;
    return ka.every((k) => Object.prototype.hasOwnProperty.call(b, k) && deepEqual(a[k], (b as JsonObject)[k]));
  }
  return false;
}

/** RFC 7386 MergePatch(target, patch); does not modify its arguments. */
export function applyMergePatch(target: Json | undefined, patch: Json): Json {
  if (!isObject(patch)) return clone(patch);
  const out: JsonObject = isObject(target) ? { ...target } : {};
  for (const [key, value] of Object.entries(patch)) {
    if (value === null) delete out[key];
    else out[key] = applyMergePatch(out[key], value);
  }
  return out;
}

/**
 * The merge patch P with applyMergePatch(base, P) deep-equal to `doc` (undefined: no change). Where `previous`
 * (an earlier patch of the same base) already says something that still holds, its entry is kept as written,
 * and its key order is kept.
 */
export function diffMergePatch(base: Json | undefined, doc: Json, previous?: Json): Json | undefined {
  if (!isObject(base) || !isObject(doc)) {
    if (deepEqual(base, doc)) {
      return previous !== undefined && deepEqual(applyMergePatch(base, previous), doc) ? previous : undefined;
    }
    return clone(doc);
  }
  const prev = isObject(previous) ? previous : undefined;
  const keys: string[] = [];
  const seen = new Set<string>();
  for (const k of [...Object.keys(prev ?? {}), ...Object.keys(doc), ...Object.keys(base)])
    if (!seen.has(k)) {
      seen.add(k);
      keys.push(k);
    }
  const out: JsonObject = {};
  for (const k of keys) {
    const inDoc = Object.prototype.hasOwnProperty.call(doc, k);
    const inBase = Object.prototype.hasOwnProperty.call(base, k);
    const p = prev && Object.prototype.hasOwnProperty.call(prev, k) ? prev[k] : undefined;
    if (!inDoc) {
      if (inBase || p === null) out[k] = null;
      continue;
    }
    if (!inBase) {
      // A new key: the whole value (a previous patch's object is applied to nothing, so it equals the value).
      out[k] = p !== undefined && p !== null && deepEqual(applyMergePatch(undefined, p), doc[k]) ? p : clone(doc[k]);
      continue;
    }
    const sub = diffMergePatch(base[k], doc[k], p === null ? undefined : p);
    if (sub !== undefined) out[k] = sub;
  }
  return Object.keys(out).length > 0 ? out : undefined;
}
