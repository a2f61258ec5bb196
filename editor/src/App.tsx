import { ReactFlowProvider, useReactFlow } from '@xyflow/react';
import { useCallback, useEffect, useMemo, useRef, useState, useSyncExternalStore } from 'react';
import * as api from './api';
import { ABPanel } from './components/ABPanel';
import { EditorContext, PreviewContext } from './components/context';
import { GraphCanvas } from './components/GraphCanvas';
import { Inspector } from './components/Inspector';
import { Palette } from './components/Palette';
import { Toolbar, type SaveAsMode } from './components/Toolbar';
import { Viewer } from './components/Viewer';
import { addNode, autoLayout, nodesOf, OUTPUT_PREFIX, removeNodes, setParam, uniqueNodeId } from './graph/document';
import { documentForServer, newVariantText, openFile, saveAsText, serializeForSave, type OpenFile } from './graph/files';
import { pointerTokens } from './graph/format';
import { deepEqual } from './graph/mergePatch';
import { dirname, join, relative } from './graph/paths';
import { schemaMap } from './graph/schema';
import { isObject, type Json, type JsonObject, type NodeSchema, type Position } from './graph/types';
import { PreviewStore } from './previews';

/** The unsaved session of a file, kept in localStorage while there are unsaved edits (so that a closed tab, a
 *  reload or a crash does not lose them) and offered back when the file is opened again. */
interface Autosave {
  path: string;
  doc: JsonObject;
  /** The file's merged document the edits were made on: the offer says when the file changed since. */
  base: JsonObject;
  at: number;
}
const autosaveKey = (path: string) => `vitrine.autosave:${path}`;
function readAutosave(path: string): Autosave | null {
  try {
    const raw = window.localStorage.getItem(autosaveKey(path));
    const value = raw ? (JSON.parse(raw) as Autosave) : null;
    return value && value.path === path && isObject(value.doc) ? value : null;
  } catch {
    return null;
  }
}
function dropAutosave(path: string) {
  try {
    window.localStorage.removeItem(autosaveKey(path));
  } catch {
    /* storage unavailable */
  }
}

interface Loaded {
  file: OpenFile;
  doc: JsonObject;
  auto: Map<string, Position>;
}

/** Where a server error points: a node (or graph output), and maybe one of its params. */
function errorTargets(errors: api.ValidationError[]) {
  const nodes = new Map<string, string>();
  const params = new Map<string, string>();
  const general: string[] = [];
  for (const e of errors) {
    const message = e.error.replace(/^.*?: \/[^ ]*: /, '');
    const t = pointerTokens(e.pointer ?? '');
    if (t[0] === 'nodes' && t[1]) {
      if (!nodes.has(t[1])) nodes.set(t[1], message);
      if (t[2] === 'params' && t[3]) params.set(`${t[1]}/${t[3]}`, message);
    } else if (t[0] === 'outputs' && t[1]) nodes.set(`${OUTPUT_PREFIX}${t[1]}`, message);
    else general.push(e.error);
  }
  return { nodes, params, general };
}

function Editor() {
  const flow = useReactFlow();
  const [schemaList, setSchemaList] = useState<NodeSchema[]>([]);
  const schemas = useMemo(() => schemaMap(schemaList), [schemaList]);
  const [graphs, setGraphs] = useState<api.GraphListEntry[]>([]);
  const [loaded, setLoaded] = useState<Loaded | null>(null);
  const [dangling, setDangling] = useState<string[]>([]);
  const [selected, setSelected] = useState<string | null>(null);
  const [status, setStatus] = useState('');
  const [errors, setErrors] = useState<api.ValidationError[]>([]);
  // Starts at 1: busy until the schemas, the graph list and the ?graph= file are loaded.
  const [pending, setPending] = useState(1);
  const [validated, setValidated] = useState<JsonObject | null>(null);
  const storeDoc = useRef<JsonObject | null>(null);
  const [viewer, setViewer] = useState<string | null>(null);
  const [abOpen, setAbOpen] = useState(false);
  const [files, setFiles] = useState<string[]>([]);
  const [offer, setOffer] = useState<Autosave | null>(null);
  const store = useMemo(() => new PreviewStore(), []);
  useEffect(() => store.connect(), [store]);
  const previewsBusy = useSyncExternalStore(store.subscribe, () => store.busy());
  const previewStatus = useSyncExternalStore(store.subscribe, () => store.status());

  const track = useCallback(async <T,>(work: Promise<T>): Promise<T> => {
    setPending((n) => n + 1);
    try {
      return await work;
    } finally {
      setPending((n) => n - 1);
    }
  }, []);
  const onBusy = useCallback((busy: boolean) => setPending((n) => n + (busy ? 1 : -1)), []);

  const open = useCallback(
    async (path: string, list = schemaList) => {
      setPending((n) => n + 1);
      try {
        const file = await openFile(path, api.readGraph);
        const map = schemaMap(list);
        setLoaded({ file, doc: file.merged, auto: autoLayout(file.merged, map) });
        const kept = readAutosave(path);
        setOffer(kept && !deepEqual(kept.doc, file.merged) ? kept : null);
        setDangling([]);
        setSelected(null);
        setErrors([]);
        setStatus(`opened ${path}${file.kind === 'variant' ? ` (variant of ${file.basePath})` : ''}`);
        const url = new URL(window.location.href);
        url.searchParams.set('graph', path);
        window.history.replaceState(null, '', url);
      } catch (e) {
        setStatus(`cannot open ${path}: ${(e as Error).message}`);
      } finally {
        setPending((n) => n - 1);
      }
    },
    [schemaList],
  );

  // Start-up: schemas, the graph list, and the file named by ?graph=.
  useEffect(() => {
    void (async () => {
      try {
        const [list, g] = await Promise.all([api.listNodes(), api.listGraphs()]);
        setSchemaList(list);
        setGraphs(g);
        const initial = new URLSearchParams(window.location.search).get('graph');
        if (initial) await open(initial, list);
      } catch (e) {
        setStatus(`cannot reach vitrine serve: ${(e as Error).message}`);
      } finally {
        setPending((n) => n - 1);
      }
    })();
    // eslint-disable-next-line react-hooks/exhaustive-deps
  }, []);

  // Files for path pickers: the server's list when it has one, else every path the served graphs name.
  useEffect(() => {
    if (graphs.length === 0 || schemas.size === 0) return;
    void (async () => {
      const fromServer = await api.listFiles();
      if (fromServer) return setFiles(fromServer);
      const found = new Set<string>();
      for (const g of graphs) {
        try {
          const doc = JSON.parse(await api.readGraph(g.path, false)) as Json;
          if (!isObject(doc)) continue;
          for (const n of Object.values(nodesOf(doc))) {
            if (!isObject(n) || typeof n.type !== 'string' || !isObject(n.params)) continue;
            for (const p of schemas.get(n.type)?.params ?? [])
              if (p.type === 'path' && typeof n.params[p.name] === 'string' && n.params[p.name])
                found.add(join(dirname(g.path), n.params[p.name] as string));
          }
        } catch {
          /* skip unreadable files */
        }
      }
      setFiles([...found].filter((f) => !f.startsWith('..')).sort());
    })();
  }, [graphs, schemas]);

  const edit = useCallback((update: (doc: JsonObject) => JsonObject) => {
    setLoaded((l) => (l ? { ...l, doc: update(l.doc) } : l));
  }, []);

  // Previews and server validation follow the document (debounced).
  useEffect(() => {
    if (!loaded || schemas.size === 0) return;
    store.update(loaded.file, loaded.doc, schemas);
    storeDoc.current = loaded.doc;
    const controller = new AbortController();
    const timer = setTimeout(() => {
      api
        .validate({ document: documentForServer(loaded.file, loaded.doc), base: loaded.file.path }, controller.signal)
        .then((errs) => {
          setErrors(errs);
          setValidated(loaded.doc);
        })
        .catch(() => undefined);
    }, 300);
    return () => {
      clearTimeout(timer);
      controller.abort();
    };
  }, [loaded, schemas, store, track]);

  useEffect(() => store.prioritize(selected), [store, selected]);

  const targets = useMemo(() => errorTargets(errors), [errors]);
  const dirty = loaded ? !deepEqual(loaded.doc, loaded.file.merged) : false;

  const addFromPalette = useCallback(
    (type: string) => {
      if (!loaded) return;
      const id = uniqueNodeId(loaded.doc, type);
      const box = document.querySelector('.canvas')?.getBoundingClientRect();
      const center = box
        ? flow.screenToFlowPosition({ x: box.left + box.width / 2, y: box.top + box.height / 2 })
        : { x: 0, y: 0 };
      edit((d) => addNode(d, id, type, { x: center.x - 100, y: center.y - 60 }));
      setSelected(id);
      flow.setNodes((nodes) => nodes.map((n) => ({ ...n, selected: n.id === id })));
      setStatus(`added ${id} (${type})`);
    },
    [loaded, flow, edit],
  );

  const write = useCallback(
    async (path: string, text: string, reopen: boolean) => {
      await track(api.writeGraph(path, text));
      dropAutosave(path);
      setStatus(`saved ${path}`);
      const g = await api.listGraphs();
      setGraphs(g);
      if (reopen) {
        const file = await openFile(path, api.readGraph);
        setLoaded((l) => (l ? { file, doc: file.merged, auto: l.auto } : l));
      }
    },
    [track],
  );

  const save = useCallback(async () => {
    if (!loaded) return;
    try {
      await write(loaded.file.path, serializeForSave(loaded.file, loaded.doc), true);
    } catch (e) {
      setStatus(`save failed: ${(e as Error).message}`);
    }
  }, [loaded, write]);

  const saveAs = useCallback(
    async (mode: SaveAsMode, path: string, description: string) => {
      if (!loaded) return;
      if (!/^[^/].*\.json$/.test(path) || path.split('/').includes('..')) {
        setStatus(`save as: expected a .json path relative to DIR, got "${path}"`);
        return;
      }
      try {
        const text =
          mode === 'variant'
            ? newVariantText(loaded.file, loaded.doc, path, description || undefined)
            : saveAsText(loaded.file, description ? { ...loaded.doc, description } : loaded.doc, path);
        await write(path, text, false);
        dropAutosave(loaded.file.path); // the edits are in the new file now
        const file = await openFile(path, api.readGraph);
        store.adopt(file); // the thumbnails stay (none re-rendered when the graph is the same)
        setLoaded((l) => (l ? { file, doc: file.merged, auto: l.auto } : l));
        const url = new URL(window.location.href);
        url.searchParams.set('graph', path);
        window.history.replaceState(null, '', url);
      } catch (e) {
        setStatus(`save failed: ${(e as Error).message}`);
      }
    },
    [loaded, write, store],
  );

  const deleteNode = useCallback(
    (id: string) => {
      edit((d) => removeNodes(d, [id]));
      setSelected(null);
      setStatus(`deleted ${id}`);
    },
    [edit],
  );

  // Busy until the previews and the server's validation have caught up with the document.
  const catchingUp = loaded !== null && schemas.size > 0 && (storeDoc.current !== loaded.doc || validated !== loaded.doc);
  const busy = pending > 0 || previewsBusy || catchingUp;

  // Unsaved edits: kept in localStorage (debounced) while the document differs from the file, and the browser asks
  // before the page is closed or reloaded.
  useEffect(() => {
    if (!loaded || !dirty) return;
    const timer = setTimeout(() => {
      try {
        const kept: Autosave = { path: loaded.file.path, doc: loaded.doc, base: loaded.file.merged, at: Date.now() };
        window.localStorage.setItem(autosaveKey(loaded.file.path), JSON.stringify(kept));
      } catch {
        /* storage full or unavailable: the beforeunload guard still asks */
      }
    }, 300);
    return () => clearTimeout(timer);
  }, [loaded, dirty]);
  useEffect(() => {
    if (!dirty) return;
    const guard = (e: BeforeUnloadEvent) => {
      e.preventDefault();
      e.returnValue = '';
    };
    window.addEventListener('beforeunload', guard);
    return () => window.removeEventListener('beforeunload', guard);
  }, [dirty]);
  const restoreOffer = useCallback(() => {
    if (!offer) return;
    setLoaded((l) => (l && l.file.path === offer.path ? { ...l, doc: offer.doc } : l));
    setStatus(`restored the unsaved edits of ${offer.path} from ${new Date(offer.at).toLocaleString()}`);
    setOffer(null);
  }, [offer]);
  const discardOffer = useCallback(() => {
    if (!offer) return;
    dropAutosave(offer.path);
    setStatus(`discarded the unsaved edits of ${offer.path}`);
    setOffer(null);
  }, [offer]);

  // Ctrl/Cmd+S saves.
  useEffect(() => {
    const onKey = (e: KeyboardEvent) => {
      if ((e.ctrlKey || e.metaKey) && e.key === 's') {
        e.preventDefault();
        void save();
      }
    };
    window.addEventListener('keydown', onKey);
    return () => window.removeEventListener('keydown', onKey);
  }, [save]);
  const callbacks = useMemo(() => ({ openViewer: (key: string) => setViewer(key) }), []);
  const fileDir = loaded ? dirname(loaded.file.path) : '';

  return (
    <PreviewContext.Provider value={store}>
      <EditorContext.Provider value={callbacks}>
        <div className="app" data-testid="app" data-state={busy ? 'busy' : 'idle'}>
          <Toolbar
            graphs={graphs}
            current={loaded?.file.path}
            kind={loaded?.file.kind}
            dirty={dirty}
            busy={busy}
            onOpen={(p) => void open(p)}
            onSave={() => void save()}
            onSaveAs={(m, p, d) => void saveAs(m, p, d)}
            onAB={() => setAbOpen(true)}
          />
          {offer && loaded?.file.path === offer.path && (
            <div className="autosave-offer" data-testid="autosave-offer">
              <span>
                Unsaved edits of {offer.path} from {new Date(offer.at).toLocaleString()}
                {deepEqual(offer.base, loaded.file.merged) ? '' : ' (the file has changed on disk since)'}.
              </span>
              <button data-testid="autosave-restore" onClick={restoreOffer}>
                Restore
              </button>
              <button data-testid="autosave-discard" onClick={discardOffer}>
                Discard
              </button>
            </div>
          )}
          <div className="main">
            <Palette schemas={schemaList} onAdd={addFromPalette} />
            <div className="canvas">
              {loaded ? (
                <GraphCanvas
                  key={loaded.file.path}
                  doc={loaded.doc}
                  schemas={schemas}
                  autoPositions={loaded.auto}
                  danglingOutputs={dangling}
                  nodeErrors={targets.nodes}
                  onEdit={edit}
                  onSelect={setSelected}
                  onStatus={setStatus}
                  onDanglingOutputs={setDangling}
                  focus={new URLSearchParams(window.location.search).get('focus')}
                />
              ) : (
                <div className="empty">Open a graph from the list above.</div>
              )}
            </div>
            {loaded && (
              <Inspector
                doc={loaded.doc}
                schemas={schemas}
                selected={selected}
                paramServerErrors={targets.params}
                files={files}
                pathValue={(p) => relative(fileDir, p)}
                onParam={(node, key, value) => edit((d) => setParam(d, node, key, value))}
                onDelete={deleteNode}
              />
            )}
          </div>
          <footer className="statusbar">
            <span data-testid="status">{status}</span>
            {previewStatus && <span className="preview-status" data-testid="preview-status">{previewStatus}</span>}
            {targets.general.length > 0 && <span className="general-error">{targets.general.join(' · ')}</span>}
            {errors.length > 0 && <span className="error-count">{errors.length} validation error{errors.length > 1 ? 's' : ''}</span>}
          </footer>
          {viewer && loaded && (
            <Viewer file={loaded.file} doc={loaded.doc} output={viewer} onClose={() => setViewer(null)} onBusy={onBusy} />
          )}
          {abOpen && (
            <ABPanel
              graphs={graphs}
              current={loaded ? { document: documentForServer(loaded.file, loaded.doc), base: loaded.file.path } : undefined}
              defaultA={loaded?.file.path}
              onClose={() => setAbOpen(false)}
              onBusy={onBusy}
            />
          )}
        </div>
      </EditorContext.Provider>
    </PreviewContext.Provider>
  );
}

export function App() {
  return (
    <ReactFlowProvider>
      <Editor />
    </ReactFlowProvider>
  );
}
