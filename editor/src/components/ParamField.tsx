// One param's widget, from its schema: a slider with numeric entry for ranges, a select for enums, a checkbox
// for bools, one entry per component for vectors (plus a swatch for colours), a text entry with a picker of
// DIR's files for paths.
import { useEffect, useState } from 'react';
import { listFiles } from '../api';
import { checkParam, hasExtension, isColorParam, pathExtensions, vectorSize } from '../graph/schema';
import type { Json, ParamSchema } from '../graph/types';

export interface ParamFieldProps {
  node: string;
  spec: ParamSchema;
  value: Json;
  explicit: boolean;
  /** The connected input that replaces this param: the widget is disabled and says so. */
  setBy?: string;
  serverError?: string;
  files: string[];
  /** Turns a DIR-relative path from the picker into the value written (relative to the graph file). */
  pathValue(dirRelative: string): string;
  onChange(value: Json | undefined): void;
}

function toHex(v: Json[]): string {
  const c = (x: Json) =>
    Math.round(Math.min(1, Math.max(0, typeof x === 'number' ? x : 0)) * 255)
      .toString(16)
      .padStart(2, '0');
  return `#${c(v[0])}${c(v[1])}${c(v[2])}`;
}

function fromHex(hex: string): number[] {
  return [1, 3, 5].map((i) => Math.round((parseInt(hex.slice(i, i + 2), 16) / 255) * 1000) / 1000);
}

const fileLists = new Map<string, Promise<string[] | null>>();

/** Files under DIR a path param can take: `GET /api/files?ext=` with the extensions its doc names (asked once per
 *  set of extensions), else `fallback` (paths found in the served graphs) filtered the same way. */
function usePathFiles(spec: ParamSchema, fallback: string[]): string[] {
  const extensions = pathExtensions(spec);
  const key = extensions.join(',');
  const [files, setFiles] = useState<string[] | null>(null);
  useEffect(() => {
    let live = true;
    if (!fileLists.has(key)) fileLists.set(key, listFiles(extensions));
    void fileLists.get(key)!.then((list) => live && setFiles(list));
    return () => {
      live = false;
    };
    // eslint-disable-next-line react-hooks/exhaustive-deps
  }, [key]);
  return files ?? fallback.filter((f) => hasExtension(f, extensions));
}

/** A path: a text entry, and a picker of the files under DIR with the extensions the param takes. */
function PathPicker(props: {
  id: string;
  spec: ParamSchema;
  value: Json;
  files: string[];
  pathValue(dirRelative: string): string;
  onChange(value: Json | undefined): void;
}) {
  const { id, spec, value, pathValue, onChange } = props;
  const files = usePathFiles(spec, props.files);
  const extensions = pathExtensions(spec).join(' ');
  return (
    <div className="col">
      <input type="text" data-testid={id} value={String(value ?? '')} onChange={(e) => onChange(e.target.value)} />
      <select data-testid={`${id}-pick`} value="" title={extensions ? `files ${extensions} under DIR` : 'files under DIR'} onChange={(e) => e.target.value && onChange(pathValue(e.target.value))}>
        <option value="">{files.length ? `Pick a file under DIR${extensions ? ` (${extensions})` : ''}…` : 'no files known'}</option>
        {files.map((f) => (
          <option key={f} value={f}>
            {f}
          </option>
        ))}
      </select>
    </div>
  );
}

/** A numeric text entry that keeps what is typed (even while it is not a number yet). */
function NumberEntry(props: {
  testid: string;
  value: Json;
  integer: boolean;
  onValue(v: number): void;
  onInvalid(message: string | null): void;
}) {
  const { testid, value, integer, onValue, onInvalid } = props;
  const [text, setText] = useState(JSON.stringify(value));
  useEffect(() => {
    setText((t) => (Number(t) === value ? t : JSON.stringify(value)));
  }, [value]);
  return (
    <input
      className="num"
      type="text"
      inputMode="decimal"
      data-testid={testid}
      value={text}
      onChange={(e) => {
        setText(e.target.value);
        const t = e.target.value.trim();
        const n = Number(t);
        if (t === '' || !Number.isFinite(n)) onInvalid(`expected ${integer ? 'an integer' : 'a number'}, got "${e.target.value}"`);
        else {
          onInvalid(null);
          onValue(n);
        }
      }}
    />
  );
}

export function ParamField(props: ParamFieldProps) {
  const { node, spec, value, explicit, setBy, serverError, files, pathValue, onChange } = props;
  const [entryError, setEntryError] = useState<string | null>(null);
  const id = `param-${node}-${spec.name}`;
  const schemaError = checkParam(spec, value);
  const error = entryError ?? schemaError ?? serverError;
  const integer = spec.type === 'int';
  const hasRange = spec.min !== undefined && spec.max !== undefined;
  let widget: JSX.Element;
  switch (spec.type) {
    case 'int':
    case 'float':
      widget = (
        <div className="row">
          {hasRange && (
            <input
              type="range"
              data-testid={`${id}-slider`}
              min={spec.min}
              max={spec.max}
              step={integer ? 1 : (spec.max! - spec.min!) / 1000}
              value={typeof value === 'number' ? value : spec.min}
              onChange={(e) => {
                setEntryError(null);
                onChange(integer ? Math.round(Number(e.target.value)) : Number(Number(e.target.value).toPrecision(6)));
              }}
            />
          )}
          <NumberEntry testid={id} value={value} integer={integer} onValue={onChange} onInvalid={setEntryError} />
        </div>
      );
      break;
    case 'bool':
      widget = <input type="checkbox" data-testid={id} checked={value === true} onChange={(e) => onChange(e.target.checked)} />;
      break;
    case 'enum':
      widget = (
        <select data-testid={id} value={typeof value === 'string' ? value : ''} onChange={(e) => onChange(e.target.value)}>
          {!(spec.choices ?? []).includes(value as string) && <option value={String(value)}>{String(value)}</option>}
          {(spec.choices ?? []).map((c) => (
            <option key={c} value={c}>
              {c}
            </option>
          ))}
        </select>
      );
      break;
    case 'string':
      widget = <input type="text" data-testid={id} value={String(value ?? '')} onChange={(e) => onChange(e.target.value)} />;
      break;
    case 'path':
      widget = (
        <PathPicker id={id} spec={spec} value={value} files={files} pathValue={pathValue} onChange={onChange} />
      );
      break;
    default: {
      const n = vectorSize(spec.type);
      const vec: Json[] = Array.isArray(value) ? value : Array.isArray(spec.default) ? spec.default : new Array(n).fill(0);
      widget = (
        <div className="row vec">
          {isColorParam(spec) && (
            <input
              type="color"
              data-testid={`${id}-color`}
              value={toHex(vec)}
              onChange={(e) => {
                const rgb = fromHex(e.target.value);
                onChange([...rgb, ...vec.slice(3)]);
              }}
            />
          )}
          {Array.from({ length: n }, (_, i) => (
            <NumberEntry
              key={i}
              testid={`${id}-${i}`}
              value={vec[i] ?? 0}
              integer={false}
              onValue={(x) => {
                const copy = [...vec];
                copy[i] = x;
                onChange(copy);
              }}
              onInvalid={setEntryError}
            />
          ))}
        </div>
      );
    }
  }
  return (
    <div className={`param ${error ? 'has-error' : ''} ${setBy ? 'set-by-input' : ''}`}>
      <label title={spec.doc}>
        <span className={explicit ? 'explicit' : ''}>{spec.name}</span>
        {hasRange && <span className="muted range">{`${spec.min}…${spec.max}`}</span>}
        {explicit && (
          <button className="reset" title={`reset to the default (${JSON.stringify(spec.default)})`} onClick={() => onChange(undefined)}>
            ↺
          </button>
        )}
      </label>
      {setBy ? (
        <fieldset disabled className="set-by" data-testid={`param-setby-${node}-${spec.name}`}>
          {widget}
          <div className="muted">set by input {setBy}</div>
        </fieldset>
      ) : (
        widget
      )}
      {spec.doc && <div className="doc">{spec.doc}</div>}
      {error && (
        <div className="param-error" data-testid={`param-error-${node}-${spec.name}`}>
          {error}
        </div>
      )}
    </div>
  );
}
