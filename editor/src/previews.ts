// Preview thumbnails of every texture output: when an edit makes some of them out of date, all the stale ones are
// rendered by one asynchronous server job (`"outputs": [...]`, compiled and rendered once), tagged
// "previews:<file>" so that a newer edit's job replaces a queued older one (its images answer 409 "superseded").
// Progress comes from the server's job events: frames of the job on every node it renders, and "node" events
// (lightmap bake, probe capture, ...) on the node named in the event.
import { ApiError, fetchImage, JobEvent, startRender, startRenderBatch, subscribeEvents } from './api';
import { documentForServer, OpenFile } from './graph/files';
import { nodeEntry, nodesOf, nodeType, stripUi, upstreamOf } from './graph/document';
import { dirname, join } from './graph/paths';
import { isObject, type JsonObject, type SchemaMap } from './graph/types';

export const PREVIEW_WIDTH = 160;
export const PREVIEW_HEIGHT = 90;
const DEBOUNCE_MS = 300;
/** The most outputs `/api/render` takes in one job. */
const MAX_OUTPUTS = 256;

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
  /** What that node is doing (stage "node"), e.g. "baking lightmap (...)". */
  label?: string;
  done?: number;
  total?: number;
}

interface Entry extends Preview {
  /** What the current image shows (undefined: nothing yet). */
  shown?: string;
  /** What it should show. */
  wanted: string;
  /** The job that renders it now, and for which signature. */
  pending?: { job: Batch; wanted: string };
}

/** One server job rendering several previews. */
interface Batch {
  id?: string;
  keys: string[];
  nodes: Set<string>;
  /** The server has begun it (an event past "queued" arrived): a newer tagged job will not replace it. */
  started: boolean;
  progress: Progress;
}

type Listener = () => void;

const isSuperseded = (e: unknown) => e instanceof ApiError && (e.status === 409 || e.body.superseded === true);

export class PreviewStore {
  private entries = new Map<string, Entry>();
  private snapshots = new Map<string, Preview>();
  private progress = new Map<string, Progress>();
  private listeners = new Set<Listener>();
  private timer: ReturnType<typeof setTimeout> | undefined;
  private batches = new Set<Batch>();
  private file: OpenFile | undefined;
  private doc: JsonObject | undefined;
  private generation = 0;
  private statusText = '';
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

  /** One line on the preview jobs (for the status bar): "" when nothing renders. */
  status(): string {
    return this.statusText;
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

  /** The open file was saved under another name (save as, save as variant): the previews stay; only those whose
   *  inputs now resolve differently (relative paths from another folder) are rendered again by the next update. */
  adopt(file: OpenFile): void {
    this.file = file;
  }

  /** The graph changed (or another file was opened): schedule what is now out of date. */
  update(file: OpenFile, doc: JsonObject, schemas: SchemaMap): void {
    if (file !== this.file && this.file?.path !== file.path) {
      for (const e of this.entries.values()) if (e.url) URL.revokeObjectURL(e.url);
      this.entries.clear();
      this.snapshots.clear();
      this.progress.clear();
      this.batches.clear();
      this.generation++;
    }
    this.file = file;
    this.doc = doc;
    const stripped = stripUi(doc);
    const keep = new Set<string>();
    // What a preview depends on: the frame and its upstream nodes, with path params resolved from the file's folder
    // (so that the same graph under another name keeps its previews, and one in another folder keeps those that
    // name no file).
    const dir = dirname(file.path);
    const resolved = (n: string) => {
      const entry = nodeEntry(stripped, n);
      const schema = schemas.get(nodeType(stripped, n));
      if (!entry || !schema || !isObject(entry.params)) return entry ?? null;
      const params = { ...entry.params };
      for (const p of schema.params)
        if (p.type === 'path' && typeof params[p.name] === 'string' && params[p.name])
          params[p.name] = join(dir, params[p.name] as string);
      return { ...entry, params };
    };
    for (const id of Object.keys(nodesOf(stripped))) {
      const schema = schemas.get(nodeType(stripped, id));
      if (!schema) continue;
      const upstream = [...upstreamOf(stripped, id)].sort();
      const signature = JSON.stringify([stripped.frame ?? null, upstream.map((n) => [n, resolved(n)])]);
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

  /** Kept for the editor's selection; all stale previews now go in one job, so there is nothing to order. */
  prioritize(_id: string | null): void {}

  /** Previews for the next job, or none when every out-of-date preview is already in a job for its current
   *  signature. A new job replaces the queued (not begun) tagged one, so that one's previews go in again. */
  private stale(): string[] {
    const keys: string[] = [];
    let uncovered = false;
    for (const [key, e] of this.entries) {
      if (e.shown === e.wanted) continue;
      const covered = e.pending !== undefined && e.pending.wanted === e.wanted;
      if (!covered) uncovered = true;
      if (!(covered && e.pending!.job.started)) keys.push(key);
    }
    return uncovered ? keys.slice(0, MAX_OUTPUTS) : [];
  }

  private async pump(): Promise<void> {
    if (!this.file || !this.doc) return;
    const keys = this.stale();
    if (keys.length === 0) return;
    const file = this.file;
    const generation = this.generation;
    const document = documentForServer(file, this.doc);
    const batch: Batch = {
      keys,
      nodes: new Set(keys.map((k) => k.slice(0, k.indexOf('.')))),
      started: false,
      progress: { stage: 'queued' },
    };
    const wanted = new Map<string, string>();
    for (const key of keys) {
      const e = this.entries.get(key)!;
      wanted.set(key, e.wanted);
      this.set(key, { ...e, pending: { job: batch, wanted: e.wanted } });
    }
    this.batches.add(batch);
    this.showProgress(batch);
    const started = performance.now();
    let urls: Record<string, string> | undefined;
    try {
      const job = await startRenderBatch(
        { document, base: file.path },
        {
          outputs: keys,
          width: PREVIEW_WIDTH,
          height: PREVIEW_HEIGHT,
          tag: `previews:${file.path}`,
          display: 'thumbnail',
        },
      );
      batch.id = job.job;
      urls = job.images;
      // Events of the job that came before its id was known (the GPU thread may begin it before the answer).
      for (const e of this.early.get(job.job) ?? []) this.onEvent(e);
      this.early.delete(job.job);
      // Every image of a job is stored at once: wait for the first, then take the others together, and show
      // them all in one update (one re-render of the canvas, not one per thumbnail).
      const [first, ...rest] = keys;
      const head = await fetchImage(urls[first]);
      const blobs = [head, ...(await Promise.all(rest.map((key) => fetchImage(urls![key]))))];
      const ms = performance.now() - started;
      keys.forEach((key, i) => this.finish(generation, batch, key, wanted.get(key)!, { url: URL.createObjectURL(blobs[i]), ms }, false));
    } catch (e) {
      if (isSuperseded(e)) {
        // A newer edit's job replaced this one: it renders these previews (those still wanted).
        for (const key of keys) this.release(generation, batch, key);
      } else {
        // One job for all failed (a node that cannot compile or run): render each preview alone, so that only
        // the previews that depend on the failing part show the error.
        await Promise.all(keys.map((key) => this.renderAlone(generation, batch, document, file, key, wanted.get(key)!)));
      }
    }
    this.batches.delete(batch);
    this.dropProgress(batch);
    this.emit();
    void this.pump();
  }

  private async renderAlone(
    generation: number,
    batch: Batch,
    document: JsonObject,
    file: OpenFile,
    key: string,
    wanted: string,
  ): Promise<void> {
    const started = performance.now();
    try {
      const job = await startRender(
        { document, base: file.path },
        { output: key, width: PREVIEW_WIDTH, height: PREVIEW_HEIGHT, display: 'thumbnail' },
      );
      const blob = await fetchImage(job.url);
      this.finish(generation, batch, key, wanted, { url: URL.createObjectURL(blob), ms: performance.now() - started });
    } catch (e) {
      this.finish(generation, batch, key, wanted, { error: (e as Error).message });
    }
  }

  /** A result (image or error) for `key` rendered at signature `wanted`. */
  private finish(
    generation: number,
    batch: Batch,
    key: string,
    wanted: string,
    result: { url?: string; ms?: number; error?: string },
    emit = true,
  ): void {
    const current = this.entries.get(key);
    if (generation !== this.generation || !current) {
      if (result.url) URL.revokeObjectURL(result.url);
      return;
    }
    if (result.url && current.url) URL.revokeObjectURL(current.url);
    const fresh = current.wanted === wanted;
    this.set(key, {
      ...current,
      ...(result.url ? { url: result.url, version: current.version + 1, ms: result.ms } : {}),
      error: result.error,
      state: fresh ? (result.url ? 'ready' : 'error') : 'loading',
      shown: wanted,
      pending: current.pending?.job === batch ? undefined : current.pending,
    });
    if (emit) this.emit();
  }

  /** `batch` will not render `key` (superseded): it is stale again unless another job covers it. */
  private release(generation: number, batch: Batch, key: string): void {
    const current = this.entries.get(key);
    if (generation !== this.generation || !current || current.pending?.job !== batch) return;
    this.set(key, { ...current, pending: undefined });
  }

  private showProgress(batch: Batch): void {
    for (const node of batch.nodes) this.progress.set(node, batch.progress);
    this.updateStatus();
    this.emit();
  }

  private dropProgress(batch: Batch): void {
    for (const node of batch.nodes) {
      const p = this.progress.get(node);
      if (p === batch.progress || (p && [...this.batches].every((b) => !b.nodes.has(node)))) this.progress.delete(node);
    }
    // A node still in another job shows that job's progress.
    for (const b of this.batches) for (const node of b.nodes) if (!this.progress.has(node)) this.progress.set(node, b.progress);
    this.updateStatus();
  }

  private updateStatus(): void {
    const running = [...this.batches].find((b) => b.started) ?? [...this.batches][0];
    if (!running) {
      this.statusText = '';
      return;
    }
    const p = running.progress;
    const frames = p.total ? ` ${p.done ?? 0}/${p.total}` : '';
    const node = p.node ? ` · ${p.node}${p.label ? `: ${p.label}` : ''}` : '';
    this.statusText = `previews (${running.keys.length}): ${p.stage}${frames}${node}`;
  }

  /** Recent events of jobs not (yet) known, by job id. */
  private early = new Map<string, JobEvent[]>();

  private onEvent(e: JobEvent): void {
    const batch = [...this.batches].find((b) => b.id !== undefined && b.id === e.job);
    if (!batch) {
      if ([...this.batches].some((b) => b.id === undefined)) {
        if (!this.early.has(e.job) && this.early.size >= 32) this.early.clear();
        this.early.set(e.job, [...(this.early.get(e.job) ?? []), e]);
      }
      return;
    }
    if (e.stage !== 'queued') batch.started = true;
    if (e.stage === 'node' && e.node) {
      // Long work inside one node: on that node (with its label), and in the status line.
      const p: Progress = { stage: e.label ?? 'working', node: e.node, label: e.label, done: e.done, total: e.total };
      this.progress.set(e.node, p);
      batch.progress = { ...batch.progress, node: e.node, label: e.label };
    } else {
      batch.progress = { stage: e.stage, done: e.done, total: e.total };
      for (const node of batch.nodes) this.progress.set(node, batch.progress);
    }
    this.updateStatus();
    this.emit();
  }
}
