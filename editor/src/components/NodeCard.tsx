// A graph node on the canvas: header (id, type), input ports on the left, outputs on the right, and a preview
// thumbnail under every texture output.
import { Handle, Position, type NodeProps, type Node } from '@xyflow/react';
import { memo, useContext } from 'react';
import type { NodeSchema } from '../graph/types';
import { EditorContext, usePreview, useProgress } from './context';

export interface NodeCardData extends Record<string, unknown> {
  id: string;
  type: string;
  schema?: NodeSchema;
  error?: string;
}

export type NodeCardNode = Node<NodeCardData, 'vitrine'>;

function Thumbnail({ node, port }: { node: string; port: string }) {
  const key = `${node}.${port}`;
  const preview = usePreview(key);
  const { openViewer } = useContext(EditorContext);
  const state = preview?.state ?? 'loading';
  return (
    <div className={`thumb thumb-${state}`} onClick={() => openViewer(key)} title={preview?.error ?? `${key}: click for the viewer`}>
      <img
        data-testid={`preview-${node}-${port}`}
        data-state={state}
        data-version={preview?.version ?? 0}
        src={preview?.url ?? EMPTY_PIXEL}
        alt={key}
        width={160}
        height={90}
        draggable={false}
      />
      {state === 'error' && <div className="thumb-error">{preview?.error}</div>}
    </div>
  );
}

const EMPTY_PIXEL = 'data:image/gif;base64,R0lGODlhAQABAAAAACH5BAEKAAEALAAAAAABAAEAAAICTAEAOw==';

function ProgressBar({ node }: { node: string }) {
  const p = useProgress(node);
  if (!p) return null;
  const fraction = p.total ? (p.done ?? 0) / p.total : undefined;
  return (
    <div className="progress" data-testid={`progress-${node}`} title={p.stage}>
      <div className={`progress-bar ${fraction === undefined ? 'indeterminate' : ''}`} style={{ width: fraction === undefined ? undefined : `${Math.round(fraction * 100)}%` }} />
      <span>
        {p.stage}
        {p.total ? ` ${p.done ?? 0}/${p.total}` : ''}
        {p.node && p.node !== node ? ` · ${p.node}` : ''}
      </span>
    </div>
  );
}

export const NodeCard = memo(function NodeCard({ data, selected }: NodeProps<NodeCardNode>) {
  const { id, type, schema, error } = data;
  const group = type.split('.')[0];
  return (
    <div className={`node-card group-${group} ${selected ? 'selected' : ''} ${error ? 'has-error' : ''}`} data-testid={`node-${id}`}>
      <div className="node-header">
        <span className="node-name">{id}</span>
        <span className="node-type">{type}</span>
      </div>
      {!schema && <div className="node-error">unknown node type "{type}"</div>}
      <div className="node-ports">
        {schema?.inputs.map((input) => (
          <div className="port port-in" key={input.name} title={`${input.kind}${input.optional ? ' (optional)' : ''}: ${input.doc ?? ''}`}>
            <Handle
              type="target"
              position={Position.Left}
              id={input.name}
              className={`handle kind-${input.kind}`}
              data-testid={`in-${id}-${input.name}`}
              data-kind={input.kind}
            />
            <span className={input.optional ? 'optional' : ''}>{input.name}</span>
          </div>
        ))}
        {schema?.outputs.map((output) => (
          <div className="port port-out" key={output.name} title={`${output.kind}${output.format ? ` (${output.format})` : ''}: ${output.doc ?? ''}`}>
            <span>{output.name}</span>
            <Handle
              type="source"
              position={Position.Right}
              id={output.name}
              className={`handle kind-${output.kind}`}
              data-testid={`out-${id}-${output.name}`}
              data-kind={output.kind}
            />
            {output.kind === 'texture' && <Thumbnail node={id} port={output.name} />}
          </div>
        ))}
      </div>
      <ProgressBar node={id} />
      {error && (
        <div className="node-error" data-testid={`node-error-${id}`}>
          {error}
        </div>
      )}
    </div>
  );
});

export interface OutputCardData extends Record<string, unknown> {
  name: string;
  error?: string;
}

export type OutputCardNode = Node<OutputCardData, 'graphOutput'>;

export const OutputCard = memo(function OutputCard({ data, selected }: NodeProps<OutputCardNode>) {
  return (
    <div className={`node-card output-card ${selected ? 'selected' : ''} ${data.error ? 'has-error' : ''}`} data-testid={`node-output-${data.name}`}>
      <div className="port port-in">
        <Handle
          type="target"
          position={Position.Left}
          id="value"
          className="handle kind-texture"
          data-testid={`in-output-${data.name}-value`}
          data-kind="texture"
        />
        <span className="node-name">⇥ {data.name}</span>
      </div>
      {data.error && (
        <div className="node-error" data-testid={`node-error-output-${data.name}`}>
          {data.error}
        </div>
      )}
    </div>
  );
});
