// The React Flow canvas: nodes and wires derived from the document; edits (move, connect, delete) go back into
// the document through `onEdit`.
import {
  applyNodeChanges,
  Background,
  BackgroundVariant,
  Controls,
  MiniMap,
  ReactFlow,
  type Connection,
  type Edge,
  type EdgeChange,
  type Node,
  type NodeChange,
  type OnSelectionChangeParams,
  useNodesInitialized,
  useReactFlow,
} from '@xyflow/react';
import { useCallback, useEffect, useMemo, useRef, useState } from 'react';
import {
  checkConnection,
  edgesOf,
  formatRef,
  nodesOf,
  nodeType,
  OUTPUT_PREFIX,
  outputsOf,
  removeNodes,
  setInput,
  setNodePosition,
  setOutput,
  setOutputPosition,
  storedPosition,
} from '../graph/document';
import type { JsonObject, PortKind, Position, SchemaMap } from '../graph/types';
import { NodeCard, OutputCard, type NodeCardData, type OutputCardData } from './NodeCard';

const nodeTypes = { vitrine: NodeCard, graphOutput: OutputCard };

const KIND_COLORS: Record<PortKind, string> = {
  texture: '#7aa2f7',
  scene: '#9ece6a',
  camera: '#e0af68',
  buffer: '#bb9af7',
};

export interface GraphCanvasProps {
  doc: JsonObject;
  schemas: SchemaMap;
  autoPositions: Map<string, Position>;
  /** Graph outputs shown though nothing feeds them (their wire was removed). */
  danglingOutputs: string[];
  nodeErrors: Map<string, string>;
  onEdit(update: (doc: JsonObject) => JsonObject): void;
  onSelect(id: string | null): void;
  onStatus(message: string): void;
  onDanglingOutputs(names: string[]): void;
  /** A node to centre on once the nodes are measured (the `?focus=` URL param), with its neighbours. */
  focus?: string | null;
}

type FlowNode = Node<NodeCardData, 'vitrine'> | Node<OutputCardData, 'graphOutput'>;

export function GraphCanvas(props: GraphCanvasProps) {
  const { doc, schemas, autoPositions, danglingOutputs, nodeErrors, onEdit, onSelect, onStatus } = props;
  const [flowNodes, setFlowNodes] = useState<FlowNode[]>([]);
  const [selectedEdges, setSelectedEdges] = useState<ReadonlySet<string>>(new Set());

  const positionOf = useCallback(
    (id: string): Position => storedPosition(doc, id) ?? autoPositions.get(id) ?? { x: 0, y: 0 },
    [doc, autoPositions],
  );

  // Reconcile the flow's nodes with the document, keeping React Flow's own state (measured size, selection).
  useEffect(() => {
    setFlowNodes((previous) => {
      const old = new Map(previous.map((n) => [n.id, n]));
      const next: FlowNode[] = [];
      for (const id of Object.keys(nodesOf(doc))) {
        const type = nodeType(doc, id);
        const data: NodeCardData = { id, type, schema: schemas.get(type), error: nodeErrors.get(id) };
        const prev = old.get(id);
        const position = prev?.dragging ? prev.position : positionOf(id);
        next.push({ ...(prev ?? {}), id, type: 'vitrine', position, data } as FlowNode);
      }
      const outputNames = [...Object.keys(outputsOf(doc)), ...danglingOutputs.filter((n) => !(n in outputsOf(doc)))];
      for (const name of outputNames) {
        const id = `${OUTPUT_PREFIX}${name}`;
        const prev = old.get(id);
        const position = prev?.dragging ? prev.position : positionOf(id);
        next.push({ ...(prev ?? {}), id, type: 'graphOutput', position, data: { name, error: nodeErrors.get(id) } } as FlowNode);
      }
      return next;
    });
  }, [doc, schemas, nodeErrors, danglingOutputs, positionOf]);

  const edges: Edge[] = useMemo(
    () =>
      edgesOf(doc).map((e) => {
        const kind = schemas.get(nodeType(doc, e.source))?.outputs.find((o) => o.name === e.sourcePort)?.kind ?? 'texture';
        return {
          id: e.id,
          selected: selectedEdges.has(e.id),
          source: e.source,
          sourceHandle: e.sourcePort,
          target: e.target,
          targetHandle: e.targetPort,
          className: e.prev ? 'vitrine-edge-prev' : `vitrine-edge kind-${kind}`,
          label: e.prev ? '@prev' : undefined,
          style: { stroke: KIND_COLORS[kind], strokeWidth: 2, strokeDasharray: e.prev ? '6 4' : undefined },
          labelStyle: { fill: '#e0af68', fontWeight: 600 },
          labelBgStyle: { fill: '#1a1b26' },
        };
      }),
    [doc, schemas, selectedEdges],
  );

  const onEdgesChange = useCallback((changes: EdgeChange<Edge>[]) => {
    setSelectedEdges((old) => {
      const next = new Set(old);
      for (const c of changes) if (c.type === 'select') c.selected ? next.add(c.id) : next.delete(c.id);
      return next;
    });
  }, []);

  const flow = useReactFlow();
  const initialized = useNodesInitialized();
  const focused = useRef(false);
  useEffect(() => {
    if (!initialized || focused.current || !props.focus || !nodesOf(doc)[props.focus]) return;
    focused.current = true;
    const near = new Set([props.focus]);
    for (const e of edgesOf(doc)) {
      if (e.target === props.focus) near.add(e.source);
      if (e.source === props.focus) near.add(e.target);
    }
    void flow.fitView({ nodes: [...near].map((id) => ({ id })), maxZoom: 1, padding: 0.1 });
  }, [initialized, doc, flow, props.focus]);

  const onNodesChange = useCallback((changes: NodeChange<FlowNode>[]) => {
    setFlowNodes((nodes) => applyNodeChanges(changes.filter((c) => c.type !== 'remove'), nodes));
  }, []);

  const onNodeDragStop = useCallback(
    (_event: unknown, _node: FlowNode, dragged: FlowNode[]) => {
      onEdit((d) => {
        let out = d;
        for (const n of dragged)
          out = n.id.startsWith(OUTPUT_PREFIX)
            ? setOutputPosition(out, n.id.slice(OUTPUT_PREFIX.length), n.position)
            : setNodePosition(out, n.id, n.position);
        return out;
      });
    },
    [onEdit],
  );

  const onConnect = useCallback(
    (c: Connection) => {
      if (!c.sourceHandle || !c.targetHandle) return;
      const r = checkConnection(doc, schemas, c.source, c.sourceHandle, c.target, c.targetHandle);
      if (!r.ok) {
        onStatus(r.message);
        return;
      }
      const output = r.output;
      if (output !== undefined) {
        onEdit((d) => setOutput(d, output, r.ref));
        props.onDanglingOutputs(danglingOutputs.filter((n) => n !== output));
        onStatus(`connected ${formatRef(r.ref)} → output ${output}`);
      } else {
        onEdit((d) => setInput(d, r.target, r.port, r.ref));
        onStatus(`connected ${formatRef(r.ref)} → ${r.target}.${r.port}`);
      }
    },
    [doc, schemas, onEdit, onStatus, danglingOutputs, props],
  );

  const onDelete = useCallback(
    ({ nodes, edges: gone }: { nodes: FlowNode[]; edges: Edge[] }) => {
      const ids = nodes.filter((n) => n.type === 'vitrine').map((n) => n.id);
      const removedOutputs = nodes.filter((n) => n.type === 'graphOutput').map((n) => n.id.slice(OUTPUT_PREFIX.length));
      const orphaned = Object.entries(outputsOf(doc))
        .filter(([, v]) => typeof v === 'string' && ids.includes(v.split('.')[0]))
        .map(([k]) => k);
      onEdit((d) => {
        let out = removeNodes(d, ids);
        for (const e of gone) {
          if (e.target.startsWith(OUTPUT_PREFIX)) out = setOutput(out, e.target.slice(OUTPUT_PREFIX.length), null);
          else if (e.targetHandle) out = setInput(out, e.target, e.targetHandle, null);
        }
        for (const name of removedOutputs) out = setOutput(out, name, null);
        return out;
      });
      const unfed = [
        ...orphaned,
        ...gone.filter((e) => e.target.startsWith(OUTPUT_PREFIX)).map((e) => e.target.slice(OUTPUT_PREFIX.length)),
      ].filter((n) => !removedOutputs.includes(n));
      props.onDanglingOutputs([...new Set([...danglingOutputs, ...unfed])].filter((n) => !removedOutputs.includes(n)));
      if (ids.length > 0) onStatus(`deleted ${ids.join(', ')}`);
    },
    [doc, onEdit, onStatus, danglingOutputs, props],
  );

  const onSelectionChange = useCallback(
    ({ nodes }: OnSelectionChangeParams) => {
      const first = nodes.find((n) => n.type === 'vitrine');
      onSelect(first ? first.id : null);
    },
    [onSelect],
  );

  return (
    <ReactFlow<FlowNode, Edge>
      nodes={flowNodes}
      edges={edges}
      nodeTypes={nodeTypes}
      onNodesChange={onNodesChange}
      onEdgesChange={onEdgesChange}
      onNodeDragStop={onNodeDragStop}
      onConnect={onConnect}
      onDelete={onDelete}
      onSelectionChange={onSelectionChange}
      deleteKeyCode={['Delete', 'Backspace']}
      colorMode="dark"
      fitView
      fitViewOptions={{ minZoom: 0.05, maxZoom: 1, padding: 0.05 }}
      minZoom={0.05}
      proOptions={{ hideAttribution: true }}
    >
      <Background variant={BackgroundVariant.Dots} gap={24} size={1} />
      <Controls />
      <MiniMap pannable zoomable nodeStrokeWidth={3} />
    </ReactFlow>
  );
}
