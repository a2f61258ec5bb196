// Preview thumbnails of every texture output: each is re-rendered (debounced) when the part of the graph it
// depends on changes, one render at a time, with progress from the server's job events.
import { fetchImage, JobEvent, startRender, subscribeEvents } from './api';
import { documentForServer, OpenFile } from './graph/files';
import { nodeEntry, nodesOf, nodeType, stripUi, upstreamOf } from './graph/document';
import type { JsonObject, SchemaMap } from './graph/types';

export const PREVIEW_WIDTH = 160;
export const PREVIEW_HEIGHT = 90;
const DEBOUNCE_MS = 300;

export type PreviewState = 'loading' | 'ready' | 'error';

export interface Preview {
  state: PreviewState;
  url?: string;
  version: number;
  error?: string;
  ms?: number;
}

export interface Progress {
  stage: string;
  /** The graph node the server is executing, when its events say so. */
  node?: string;
  done?: number;
  total?: number;
}

interface Entry extends Preview {
  /** What the current image shows (undefined: nothing yet). */
  shown?: string;
  /** What it should show. */
  wanted: string;
}

type Listener = () => void;

export class PreviewStore {
  private entries = new Map<string, Entry>();
  private snapshots = new Map<string, Preview>();
  private progress = new Map<string, Progress>();
  private listeners = new Set<Listener>();
  private timer: ReturnType<typeof setTimeout> | undefined;
  private running: { key: string; job?: string; node: string } | undefined;
  private file: OpenFile | undefined;
  private doc: JsonObject | undefined;
  private generation = 0;
  /** Listens to the server's job events (for progress) until the returned function is called. */
  connect(): () => void {
    const stop = subscribeEvents((e) => this.onEvent(e));
    return () => {
      stop();
      clearTimeout(this.timer);
    };
  }

  subscribe = (fn: Listener): (() => void) => {
    this.listeners.add(fn);
    return () => this.listeners.delete(fn);
  };

  private emit(): void {
    for (const fn of this.listeners) fn();
  }

  get(key: string): Preview | undefined {
    return this.snapshots.get(key);
  }

  progressOf(node: string): Progress | undefined {
    return this.progress.get(node);
  }

  /** True while any preview waits for an image. */
  busy(): boolean {
    for (const e of this.entries.values()) if (e.shown !== e.wanted) return true;
    return false;
  }

  private set(key: string, e: Entry): void {
    this.entries.set(key, e);
    this.snapshots.set(key, { state: e.state, url: e.url, version: e.version, error: e.error, ms: e.ms });
  }

  /** The graph changed (or another file was opened): schedule what is now out of date. */
  update(file: OpenFile, doc: JsonObject, schemas: SchemaMap): void {
    if (file !== this.file && this.file?.path !== file.path) {
      for (const e of this.entries.values()) if (e.url) URL.revokeObjectURL(e.url);
      this.entries.clear();
      this.snapshots.clear();
      this.generation++;
    }
    this.file = file;
    this.doc = doc;
    const stripped = stripUi(doc);
    const keep = new Set<string>();
    for (const id of Object.keys(nodesOf(stripped))) {
      const schema = schemas.get(nodeType(stripped, id));
      if (!schema) continue;
      const upstream = [...upstreamOf(stripped, id)].sort();
      const signature = JSON.stringify([
        file.path,
        stripped.frame ?? null,
        upstream.map((n) => [n, nodeEntry(stripped, n)]),
      ]);
      for (const out of schema.outputs) {
        if (out.kind !== 'texture') continue;
        const key = `${id}.${out.name}`;
        keep.add(key);
        const old = this.entries.get(key);
        if (!old) this.set(key, { state: 'loading', version: 0, wanted: signature });
        else if (old.wanted !== signature) this.set(key, { ...old, state: 'loading', error: undefined, wanted: signature });
      }
    }
    for (const [key, e] of this.entries)
      if (!keep.has(key)) {
        if (e.url) URL.revokeObjectURL(e.url);
        this.entries.delete(key);
        this.snapshots.delete(key);
      }
    this.emit();
    clearTimeout(this.timer);
    this.timer = setTimeout(() => void this.pump(), DEBOUNCE_MS);
  }

  private first: string | null = null;

  /** Renders the previews of node `id` (the selected one) before the others. */
  prioritize(id: string | null): void {
    this.first = id;
  }

  private next(): [string, Entry] | undefined {
    let fallback: [string, Entry] | undefined;
    for (const [key, e] of this.entries)
      if (e.shown !== e.wanted) {
        if (this.first !== null && key.startsWith(`${this.first}.`)) return [key, e];
        fallback ??= [key, e];
      }
    return fallback;
  }

  private async pump(): Promise<void> {
    if (this.running || !this.file || !this.doc) return;
    const item = this.next();
    if (!item) return;
    const [key, entry] = item;
    const node = key.slice(0, key.indexOf('.'));
    const wanted = entry.wanted;
    const generation = this.generation;
    const file = this.file;
    this.running = { key, node };
    this.progress.set(node, { stage: 'queued' });
    this.emit();
    let result: Partial<Entry>;
    try {
      const started = performance.now();
      const job = await startRender(
        { document: documentForServer(file, this.doc), base: file.path },
        { output: key, width: PREVIEW_WIDTH, height: PREVIEW_HEIGHT },
      );
      if (this.running) this.running.job = job.job;
      const blob = await fetchImage(job.url);
      result = { state: 'ready', url: URL.createObjectURL(blob), error: undefined, ms: performance.now() - started };
    } catch (e) {
      result = { state: 'error', error: (e as Error).message };
    }
    this.running = undefined;
    this.progress.delete(node);
    const current = this.entries.get(key);
    if (generation === this.generation && current) {
      if (result.url && current.url) URL.revokeObjectURL(current.url);
      const fresh = current.wanted === wanted;
      this.set(key, {
        ...current,
        ...(result.url ? { url: result.url, version: current.version + 1, ms: result.ms } : {}),
        error: result.error,
        state: fresh ? (result.state as PreviewState) : 'loading',
        shown: wanted,
      });
    } else if (result.url) URL.revokeObjectURL(result.url);
    this.emit();
    void this.pump();
  }

  private onEvent(e: JobEvent): void {
    if (!this.running || e.job !== this.running.job) return;
    this.progress.set(this.running.node, { stage: e.stage, done: e.done, total: e.total, node: e.node });
    this.emit();
  }
}
