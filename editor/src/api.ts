// The `vitrine serve` JSON API (README "Serving graphs"). Every request carries the access token when the page
// was opened with `?token=T` (the server also keeps it as a cookie).
import type { Json, JsonObject, NodeSchema } from './graph/types';

const token = new URLSearchParams(window.location.search).get('token');

function headers(extra: Record<string, string> = {}): Record<string, string> {
  return token ? { ...extra, Authorization: `token ${token}` } : extra;
}

export class ApiError extends Error {
  constructor(
    readonly status: number,
    message: string,
    readonly body: JsonObject = {},
  ) {
    super(message);
  }
  get pointer(): string | undefined {
    return typeof this.body.pointer === 'string' ? this.body.pointer : undefined;
  }
}

async function failure(res: Response): Promise<ApiError> {
  let body: JsonObject = {};
  try {
    body = (await res.json()) as JsonObject;
  } catch {
    /* not JSON */
  }
  const message = typeof body.error === 'string' ? body.error : `${res.status} ${res.statusText}`;
  return new ApiError(res.status, message, body);
}

async function getJson<T>(url: string): Promise<T> {
  const res = await fetch(url, { headers: headers() });
  if (!res.ok) throw await failure(res);
  return (await res.json()) as T;
}

/** A POST; a 503 with Retry-After (the server's GPU queue is full: other tabs or scripts render) is tried again
 *  after the time it names, up to 5 times, before its answer is handed back. */
async function postJson(url: string, body: JsonObject, signal?: AbortSignal): Promise<Response> {
  for (let attempt = 0; ; ++attempt) {
    const res = await fetch(url, {
      method: 'POST',
      headers: headers({ 'Content-Type': 'application/json' }),
      body: JSON.stringify(body),
      signal,
    });
    const retry = Number(res.headers.get('Retry-After'));
    if (res.status !== 503 || !(retry > 0) || attempt >= 5 || signal?.aborted) return res;
    await new Promise((r) => setTimeout(r, Math.min(retry, 10) * 1000));
    if (signal?.aborted) return res;
  }
}

export interface GraphListEntry {
  path: string;
  kind: 'graph' | 'variant';
  extends?: string;
  description?: string;
}

export const listGraphs = async (): Promise<GraphListEntry[]> =>
  (await getJson<{ graphs: GraphListEntry[] }>('/api/graphs')).graphs;

export const listNodes = (): Promise<NodeSchema[]> => getJson<NodeSchema[]>('/api/nodes');

/** The ETag of each graph file as this page last read or wrote it: a save sends it as If-Match, so that a file changed
 * since (another tab, another editor) is not overwritten: the server answers 412 and the save fails with its message. */
const etags = new Map<string, string>();

/** A graph file's text; `track` (default) keeps its ETag for the next `writeGraph` of that path. */
export async function readGraph(path: string, track = true): Promise<string> {
  const res = await fetch(`/api/graphs/${path.split('/').map(encodeURIComponent).join('/')}`, { headers: headers() });
  if (!res.ok) throw await failure(res);
  const etag = res.headers.get('ETag');
  if (track && etag) etags.set(path, etag);
  return res.text();
}

export async function writeGraph(path: string, text: string): Promise<void> {
  const known = etags.get(path);
  const res = await fetch(`/api/graphs/${path.split('/').map(encodeURIComponent).join('/')}`, {
    method: 'PUT',
    headers: headers(known ? { 'Content-Type': 'application/json', 'If-Match': known } : { 'Content-Type': 'application/json' }),
    body: text,
  });
  if (!res.ok) throw await failure(res);
  const etag = res.headers.get('ETag');
  if (etag) etags.set(path, etag);
}

/** A graph for a request: a file under DIR, or a document sent inline standing for the file `base`. */
export type GraphRef = { graph: string } | { document: JsonObject; base?: string };

export interface ValidationError {
  error: string;
  file?: string;
  pointer?: string;
}

export async function validate(graph: GraphRef, signal?: AbortSignal): Promise<ValidationError[]> {
  const res = await postJson('/api/validate', graph as JsonObject, signal);
  let body: JsonObject = {};
  try {
    body = (await res.json()) as JsonObject;
  } catch {
    /* empty */
  }
  if (res.ok && body.ok === true) return [];
  if (Array.isArray(body.errors)) return body.errors as unknown as ValidationError[];
  if (typeof body.error === 'string')
    return [{ error: body.error, file: body.file as string | undefined, pointer: body.pointer as string | undefined }];
  return [{ error: `${res.status} ${res.statusText}` }];
}

export interface RenderJob {
  job: string;
  image: string;
  url: string;
}

/** Starts an asynchronous render (`"async": true`); fetch the image with `fetchImage`. */
export async function startRender(
  graph: GraphRef,
  options: { output: string; width: number; height: number; frames?: number; display?: 'thumbnail' },
  signal?: AbortSignal,
): Promise<RenderJob> {
  const res = await postJson('/api/render', { ...(graph as JsonObject), ...options, async: true }, signal);
  if (res.status !== 202 && !res.ok) throw await failure(res);
  return (await res.json()) as RenderJob;
}

export interface RenderBatch {
  job: string;
  /** "node.port" -> image URL (202 until the job is done, 409 when a newer job with the same tag replaced it). */
  images: Record<string, string>;
}

/** Starts one asynchronous render of several outputs ("node.port"): compiled and rendered once. A render with
 *  the same `tag` replaces this one while it is still queued. */
export async function startRenderBatch(
  graph: GraphRef,
  options: { outputs: string[]; width: number; height: number; tag?: string; display?: 'thumbnail' },
  signal?: AbortSignal,
): Promise<RenderBatch> {
  const res = await postJson('/api/render', { ...(graph as JsonObject), ...options, async: true }, signal);
  if (res.status !== 202 && !res.ok) throw await failure(res);
  return (await res.json()) as RenderBatch;
}

const sleep = (ms: number) => new Promise((r) => setTimeout(r, ms));

/** The PNG at `url` once it is ready (the server answers 202 while it is pending). */
export async function fetchImage(url: string, signal?: AbortSignal): Promise<Blob> {
  for (let wait = 50; ; wait = Math.min(wait * 1.5, 500)) {
    const res = await fetch(url, { headers: headers(), signal });
    if (res.status === 200) return res.blob();
    if (res.status !== 202) throw await failure(res);
    await sleep(wait);
  }
}

export interface CompareResult {
  metrics: JsonObject;
  images: { a: string; b: string; diff: string; flip: string };
}

export async function compare(
  a: GraphRef | string,
  b: GraphRef | string,
  options: { width: number; height: number; output?: string },
): Promise<CompareResult> {
  const res = await postJson('/api/compare', { a: a as Json, b: b as Json, ...options });
  if (!res.ok) throw await failure(res);
  return (await res.json()) as CompareResult;
}

export interface JobEvent {
  job: string;
  kind: string;
  graph?: string;
  stage: 'queued' | 'compiling' | 'rendering' | 'done' | 'error' | string;
  done?: number;
  total?: number;
  /** For stage "node": the graph node doing long work, and what (e.g. "baking lightmap (...)"). */
  node?: string;
  label?: string;
  ms?: number;
  error?: string;
}

/** Server-sent job events; returns a function that stops listening. */
export function subscribeEvents(onJob: (e: JobEvent) => void): () => void {
  if (typeof EventSource === 'undefined') return () => undefined;
  const url = token ? `/api/events?token=${encodeURIComponent(token)}` : '/api/events';
  let source: EventSource | null = null;
  let timer: ReturnType<typeof setTimeout> | undefined;
  let stopped = false;
  const open = () => {
    const s = new EventSource(url);
    source = s;
    s.addEventListener('job', (ev) => {
      try {
        onJob(JSON.parse((ev as MessageEvent<string>).data) as JobEvent);
      } catch {
        /* ignore malformed events */
      }
    });
    // A stream the server refuses (503: too many streams open, from other tabs) is closed for good by the browser:
    // try again a little later. Network errors reconnect by themselves (readyState CONNECTING).
    s.addEventListener('error', () => {
      if (!stopped && s.readyState === EventSource.CLOSED) timer = setTimeout(open, 5000);
    });
  };
  open();
  return () => {
    stopped = true;
    clearTimeout(timer);
    source?.close();
  };
}

/** Files under DIR for path pickers: `GET /api/files[?ext=.cube,.png]` when the server has it, else none. */
export async function listFiles(extensions: string[] = []): Promise<string[] | null> {
  try {
    const query = extensions.length ? `?ext=${extensions.map(encodeURIComponent).join(',')}` : '';
    const res = await fetch(`/api/files${query}`, { headers: headers() });
    if (!res.ok) return null;
    const body = (await res.json()) as { files?: string[] };
    return Array.isArray(body.files) ? body.files : null;
  } catch {
    return null;
  }
}
