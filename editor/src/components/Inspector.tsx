// The selected node's params, each with the widget its schema asks for.
import { nodeEntry, nodeParams, nodeType } from '../graph/document';
import { isObject, type Json, type JsonObject, type SchemaMap } from '../graph/types';
import { paramsSetByInputs } from '../graph/schema';
import { ParamField } from './ParamField';

export interface InspectorProps {
  doc: JsonObject;
  schemas: SchemaMap;
  selected: string | null;
  paramServerErrors: Map<string, string>;
  files: string[];
  pathValue(dirRelative: string): string;
  onParam(node: string, key: string, value: Json | undefined): void;
  onDelete(node: string): void;
}

export function Inspector(props: InspectorProps) {
  const { doc, schemas, selected, paramServerErrors, files, pathValue, onParam, onDelete } = props;
  const node = selected ? nodeEntry(doc, selected) : undefined;
  if (!selected || !node)
    return (
      <aside className="inspector" data-testid="inspector">
        <p className="muted">Select a node to edit its params.</p>
      </aside>
    );
  const type = nodeType(doc, selected);
  const schema = schemas.get(type);
  const params = nodeParams(doc, selected);
  const unknown = Object.keys(params).filter((k) => !schema?.params.some((p) => p.name === k));
  // A param that a connected input replaces (tonemap's exposure while camera_state is wired) does nothing: shown
  // disabled, naming the input.
  const connected = isObject(node.in) ? node.in : {};
  const setBy = paramsSetByInputs(schema);
  return (
    <aside className="inspector" data-testid="inspector">
      <div className="inspector-head">
        <h2 data-testid="inspector-name">{selected}</h2>
        <button className="danger" data-testid="delete-node" onClick={() => onDelete(selected)} title="Delete this node">
          Delete
        </button>
      </div>
      <div className="node-type">{type}</div>
      {schema?.doc && <p className="doc">{schema.doc}</p>}
      {schema?.params.map((spec) => (
        <ParamField
          key={`${selected}/${spec.name}`}
          node={selected}
          spec={spec}
          value={spec.name in params ? params[spec.name] : spec.default}
          explicit={spec.name in params}
          setBy={setBy.has(spec.name) && setBy.get(spec.name)! in connected ? setBy.get(spec.name) : undefined}
          serverError={paramServerErrors.get(`${selected}/${spec.name}`)}
          files={files}
          pathValue={pathValue}
          onChange={(v) => onParam(selected, spec.name, v)}
        />
      ))}
      {schema && schema.params.length === 0 && <p className="muted">No params.</p>}
      {unknown.map((k) => (
        <div className="param has-error" key={k}>
          <label>{k}</label>
          <div className="param-error" data-testid={`param-error-${selected}-${k}`}>
            node type {type} has no param '{k}'
          </div>
          <button onClick={() => onParam(selected, k, undefined)}>remove</button>
        </div>
      ))}
      {isObject(node.in) && Object.keys(node.in).length > 0 && (
        <div className="inputs-list">
          <h3>Inputs</h3>
          {Object.entries(node.in).map(([port, ref]) => (
            <div key={port} className="muted">
              {port} ← {String(ref)}
            </div>
          ))}
        </div>
      )}
    </aside>
  );
}
