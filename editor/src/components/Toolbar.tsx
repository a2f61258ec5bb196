// Open / save / save as (graph or variant) / A/B.
import { useEffect, useState } from 'react';
import type { GraphListEntry } from '../api';

export type SaveAsMode = 'variant' | 'graph';

export interface ToolbarProps {
  graphs: GraphListEntry[];
  current?: string;
  kind?: 'graph' | 'variant';
  dirty: boolean;
  busy: boolean;
  onOpen(path: string): void;
  onSave(): void;
  onSaveAs(mode: SaveAsMode, path: string, description: string): void;
  onAB(): void;
}

export function Toolbar(props: ToolbarProps) {
  const { graphs, current, kind, dirty, busy, onOpen, onSave, onSaveAs, onAB } = props;
  const [choice, setChoice] = useState(current ?? '');
  const [saveAs, setSaveAs] = useState<SaveAsMode | null>(null);
  const [path, setPath] = useState('');
  const [description, setDescription] = useState('');
  useEffect(() => {
    if (current) setChoice(current);
  }, [current]);
  useEffect(() => {
    if (!saveAs || !current) return;
    const stem = current.replace(/^.*\//, '').replace(/\.json$/, '');
    setPath(saveAs === 'variant' ? `graphs/variants/${stem}_variant.json` : current.replace(/\.json$/, '_copy.json'));
  }, [saveAs, current]);
  return (
    <header className="toolbar">
      <span className="brand">vitrine</span>
      <select data-testid="graph-list" value={choice} onChange={(e) => setChoice(e.target.value)}>
        <option value="" disabled>
          Choose a graph…
        </option>
        {graphs.map((g) => (
          <option key={g.path} value={g.path} title={g.description}>
            {g.kind === 'variant' ? `  ↳ ${g.path}` : g.path}
          </option>
        ))}
      </select>
      <button data-testid="open-graph" onClick={() => choice && onOpen(choice)} disabled={!choice}>
        Open
      </button>
      {current && (
        <span className="current">
          <span data-testid="current-file">{current}</span>
          {kind === 'variant' && <span className="badge">variant</span>}
          {dirty && (
            <span className="dirty" data-testid="dirty" title="unsaved edits">
              ●
            </span>
          )}
        </span>
      )}
      <button data-testid="save" onClick={onSave} disabled={!current}>
        Save
      </button>
      <button data-testid="save-as-variant" onClick={() => setSaveAs('variant')} disabled={!current}>
        Save as variant…
      </button>
      <button data-testid="save-as" onClick={() => setSaveAs('graph')} disabled={!current}>
        Save as…
      </button>
      <button data-testid="ab-open" onClick={onAB}>
        A/B
      </button>
      <span className={`activity ${busy ? 'on' : ''}`} title={busy ? 'working' : 'idle'} />
      {saveAs && (
        <div className="save-as">
          <span>{saveAs === 'variant' ? 'New variant of the open graph:' : 'Save the whole graph as:'}</span>
          <input data-testid="save-as-path" value={path} onChange={(e) => setPath(e.target.value)} size={40} />
          <input
            data-testid="save-as-description"
            placeholder="description (optional)"
            value={description}
            onChange={(e) => setDescription(e.target.value)}
            size={30}
          />
          <button
            data-testid="save-as-confirm"
            onClick={() => {
              onSaveAs(saveAs, path.trim(), description.trim());
              setSaveAs(null);
              setDescription('');
            }}
          >
            Write
          </button>
          <button onClick={() => setSaveAs(null)}>Cancel</button>
        </div>
      )}
    </header>
  );
}
