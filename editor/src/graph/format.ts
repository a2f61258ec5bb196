// Writes graph files the way the shipped ones are written: an indented outer structure, and any value that fits
// on its line as compact one-line JSON (`{"type": "aa.fxaa", "in": {"color": "pattern.color"}}`). Values that
// did not change since the file was read are copied from its text as they were (numbers like `6.0`, hand-made
// line breaks), so saving an unchanged file gives the same bytes and an edit changes only the lines it touches.
import { deepEqual } from './mergePatch';
import { isObject, Json } from './types';

export interface Span {
  start: number;
  end: number;
  value: Json;
}

/** JSON pointer token escaping (RFC 6901). */
export function pointerToken(key: string): string {
  return key.replace(/~/g, '~0').replace(/\//g, '~1');
}

export function pointerTokens(pointer: string): string[] {
  if (pointer === '' || pointer === '/') return [];
  return pointer
    .replace(/^\//, '')
    .split('/')
    .map((t) => t.replace(/~1/g, '/').replace(/~0/g, '~'));
}

/** Parses JSON text and records where every value's text starts and ends, keyed by JSON pointer. */
export function parseWithSpans(text: string): { value: Json; spans: Map<string, Span> } {
  const spans = new Map<string, Span>();
  let i = 0;
  const ws = () => {
    while (i < text.length && ' \t\r\n'.includes(text[i])) i++;
  };
  const fail = (what: string): never => {
    throw new SyntaxError(`JSON: ${what} at byte ${i}`);
  };
  const parseValue = (ptr: string): Json => {
    ws();
    const start = i;
    let value: Json;
    const c = text[i];
    if (c === '{') {
      i++;
      const obj: { [k: string]: Json } = {};
      ws();
      if (text[i] === '}') i++;
      else
        for (;;) {
          ws();
          if (text[i] !== '"') fail('expected a key');
          const key = parseString();
          ws();
          if (text[i] !== ':') fail("expected ':'");
          i++;
          obj[key] = parseValue(`${ptr}/${pointerToken(key)}`);
          ws();
          if (text[i] === ',') i++;
          else if (text[i] === '}') {
            i++;
            break;
          } else fail("expected ',' or '}'");
        }
      value = obj;
    } else if (c === '[') {
      i++;
      const arr: Json[] = [];
      ws();
      if (text[i] === ']') i++;
      else
        for (;;) {
          arr.push(parseValue(`${ptr}/${arr.length}`));
          ws();
          if (text[i] === ',') i++;
          else if (text[i] === ']') {
            i++;
            break;
          } else fail("expected ',' or ']'");
        }
      value = arr;
    } else if (c === '"') {
      value = parseString();
    } else {
      const m = /^(-?\d+(\.\d+)?([eE][+-]?\d+)?|true|false|null)/.exec(text.slice(i, i + 64));
      if (!m) fail('expected a value');
      i += m![0].length;
      value = JSON.parse(m![0]) as Json;
    }
    spans.set(ptr, { start, end: i, value });
    return value;
  };
  const parseString = (): string => {
    const start = i;
    i++;
    while (i < text.length && text[i] !== '"') i += text[i] === '\\' ? 2 : 1;
    if (i >= text.length) fail('unterminated string');
    i++;
    return JSON.parse(text.slice(start, i)) as string;
  };
  const value = parseValue('');
  ws();
  if (i !== text.length) fail('trailing characters');
  return { value, spans };
}

export interface FormatOptions {
  /** The file's previous text: unchanged values are copied from it. */
  original?: string;
  indent?: string;
  width?: number;
}

/** The indentation unit of a JSON text (the first indented line's leading blanks), default two spaces. */
export function detectIndent(text: string): string {
  const m = /\n([ \t]+)\S/.exec(text);
  return m ? m[1] : '  ';
}

/** One-line JSON; `reuse` may supply the original text of an unchanged value (e.g. `1.0` stays `1.0`). */
function compact(v: Json, ptr = '', reuse?: (v: Json, ptr: string) => string | undefined): string {
  const old = reuse?.(v, ptr);
  if (old !== undefined && !old.includes('\n')) return old;
  if (Array.isArray(v)) return `[${v.map((x, i) => compact(x, `${ptr}/${i}`, reuse)).join(', ')}]`;
  if (isObject(v))
    return `{${Object.entries(v)
      .map(([k, x]) => `${JSON.stringify(k)}: ${compact(x, `${ptr}/${pointerToken(k)}`, reuse)}`)
      .join(', ')}}`;
  return JSON.stringify(v);
}

export function formatJson(value: Json, options: FormatOptions = {}): string {
  const original = options.original;
  let spans: Map<string, Span> | undefined;
  if (original !== undefined) {
    try {
      spans = parseWithSpans(original).spans;
    } catch {
      spans = undefined;
    }
  }
  const unit = options.indent ?? (original ? detectIndent(original) : '  ');
  // Lines as long as the file's longest (at least 120 columns): edits keep the author's layout.
  // (Lines holding a single string, like a long description, do not count.)
  const structural = (original ?? '').split('\n').filter((l) => !/^\s*"[^"]*": "(?:[^"\\]|\\.)*",?$/.test(l));
  const width = options.width ?? Math.min(200, Math.max(120, ...structural.map((l) => l.length)));
  const lineIndentAt = (pos: number): string => {
    const lineStart = original!.lastIndexOf('\n', pos - 1) + 1;
    return /^[ \t]*/.exec(original!.slice(lineStart))![0];
  };

  const reuse = (v: Json, ptr: string): string | undefined => {
    const old = spans?.get(ptr);
    return old && deepEqual(old.value, v) ? original!.slice(old.start, old.end) : undefined;
  };
  const fmt = (v: Json, ptr: string, indent: string, column: number): string => {
    const old = spans?.get(ptr);
    if (old && deepEqual(old.value, v)) {
      const text = original!.slice(old.start, old.end);
      if (!text.includes('\n') || lineIndentAt(old.start) === indent) return text;
    }
    const one = compact(v, ptr, spans ? reuse : undefined);
    const container = Array.isArray(v) ? v.length > 0 : isObject(v) && Object.keys(v).length > 0;
    if (!container || (ptr !== '' && column + one.length <= width)) return one;
    const inner = indent + unit;
    if (Array.isArray(v)) {
      const items = v.map((x, i) => inner + fmt(x, `${ptr}/${i}`, inner, inner.length));
      return `[\n${items.join(',\n')}\n${indent}]`;
    }
    const items = Object.entries(v as Record<string, Json>).map(([k, x]) => {
      const head = `${inner}${JSON.stringify(k)}: `;
      return head + fmt(x, `${ptr}/${pointerToken(k)}`, inner, head.length);
    });
    return `{\n${items.join(',\n')}\n${indent}}`;
  };

  const trailing = original === undefined ? '\n' : (/\s*$/.exec(original)?.[0] ?? '');
  return fmt(value, '', '', 0) + trailing;
}
