// The large viewer: a texture output rendered through a `debug.view` node (channel, value range) at a larger
// size, so HDR values map to the display as `debug.view` maps them.
import { useEffect, useState } from 'react';
import { fetchImage, startRender } from '../api';
import { documentForServer, type OpenFile } from '../graph/files';
import { uniqueNodeId } from '../graph/document';
import type { JsonObject } from '../graph/types';

const CHANNELS: Record<string, string> = { rgb: 'rgb', r: 'r', g: 'g', b: 'b', a: 'a', luminance: 'luma' };

export function Viewer(props: { file: OpenFile; doc: JsonObject; output: string; onClose(): void; onBusy(busy: boolean): void }) {
  const { file, doc, output, onClose, onBusy } = props;
  const [channel, setChannel] = useState('rgb');
  const [min, setMin] = useState('0');
  const [max, setMax] = useState('1');
  const [url, setUrl] = useState<string>();
  const [error, setError] = useState<string>();
  const [loading, setLoading] = useState(false);

  useEffect(() => {
    const lo = Number(min);
    const hi = Number(max);
    if (!Number.isFinite(lo) || !Number.isFinite(hi)) {
      setError('min and max must be numbers');
      return;
    }
    let cancelled = false;
    // Busy (and the image "loading") from the change on, through the debounce, until the new image is shown.
    let released = false;
    const release = () => {
      if (!released) {
        released = true;
        onBusy(false);
      }
    };
    setLoading(true);
    onBusy(true);
    const view = uniqueNodeId(doc, 'debug.view');
    const [node, port] = output.split('.');
    const viewed: JsonObject = {
      ...doc,
      nodes: {
        ...(doc.nodes as JsonObject),
        [view]: { type: 'debug.view', in: { texture: `${node}.${port}` }, params: { channel: CHANNELS[channel], range: [lo, hi] } },
      },
    };
    const timer = setTimeout(async () => {
      try {
        const job = await startRender({ document: documentForServer(file, viewed), base: file.path }, { output: `${view}.color`, width: 960, height: 540 });
        const blob = await fetchImage(job.url);
        if (!cancelled) {
          setUrl((old) => {
            if (old) URL.revokeObjectURL(old);
            return URL.createObjectURL(blob);
          });
          setError(undefined);
        }
      } catch (e) {
        if (!cancelled) setError((e as Error).message);
      } finally {
        if (!cancelled) setLoading(false);
        release();
      }
    }, 200);
    return () => {
      cancelled = true;
      clearTimeout(timer);
      release();
    };
  }, [file, doc, output, channel, min, max, onBusy]);

  return (
    <div className="modal" onClick={onClose}>
      <div className="viewer" data-testid="viewer" onClick={(e) => e.stopPropagation()}>
        <div className="viewer-bar">
          <strong>{output}</strong>
          <label>
            channel{' '}
            <select data-testid="viewer-channel" value={channel} onChange={(e) => setChannel(e.target.value)}>
              {Object.keys(CHANNELS).map((c) => (
                <option key={c}>{c}</option>
              ))}
            </select>
          </label>
          <label>
            min <input className="num" data-testid="viewer-min" value={min} onChange={(e) => setMin(e.target.value)} />
          </label>
          <label>
            max <input className="num" data-testid="viewer-max" value={max} onChange={(e) => setMax(e.target.value)} />
          </label>
          {loading && <span className="muted">rendering…</span>}
          <button data-testid="viewer-close" onClick={onClose}>
            Close
          </button>
        </div>
        {error && <div className="param-error">{error}</div>}
        <img data-testid="viewer-image" data-state={loading ? 'loading' : error ? 'error' : 'ready'} src={url} alt={output} />
      </div>
    </div>
  );
}
