// Node types from GET /api/nodes, grouped by type prefix and searchable; a click adds one.
import { useMemo, useState } from 'react';
import { typeGroup } from '../graph/schema';
import type { NodeSchema } from '../graph/types';

export function Palette({ schemas, onAdd }: { schemas: NodeSchema[]; onAdd(type: string): void }) {
  const [query, setQuery] = useState('');
  const groups = useMemo(() => {
    const q = query.trim().toLowerCase();
    const map = new Map<string, NodeSchema[]>();
    for (const s of schemas) {
      if (q && !s.type.toLowerCase().includes(q) && !(s.doc ?? '').toLowerCase().includes(q)) continue;
      const g = typeGroup(s.type);
      if (!map.has(g)) map.set(g, []);
      map.get(g)!.push(s);
    }
    return [...map.entries()].sort(([a], [b]) => a.localeCompare(b));
  }, [schemas, query]);
  return (
    <aside className="palette" data-testid="palette">
      <input
        className="search"
        data-testid="palette-search"
        placeholder="Search nodes…"
        value={query}
        onChange={(e) => setQuery(e.target.value)}
      />
      <div className="palette-groups">
        {groups.map(([group, list]) => (
          <section key={group} className="palette-group" data-testid={`palette-group-${group}`}>
            <h3>{group}</h3>
            {list.map((s) => (
              <button
                key={s.type}
                className={`palette-item group-${group}`}
                data-testid={`palette-item-${s.type}`}
                title={s.doc}
                onClick={() => onAdd(s.type)}
              >
                {s.type.slice(group.length + 1) || s.type}
              </button>
            ))}
          </section>
        ))}
        {groups.length === 0 && <p className="muted">No node type matches.</p>}
      </div>
    </aside>
  );
}
